// meshes/strip_footing.geo on a 4B x 4B block (B = 1; docs/contact.md).
W = 4;
D = 4;
Include "strip_footing.geo";
