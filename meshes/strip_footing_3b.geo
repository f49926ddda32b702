// meshes/strip_footing.geo on a 3B x 3B block (B = 1; docs/contact.md).
W = 3;
D = 3;
Include "strip_footing.geo";
