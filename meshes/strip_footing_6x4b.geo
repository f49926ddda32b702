// meshes/strip_footing.geo on a 6B wide, 4B deep block (B = 1): room for the c-phi
// footing's mechanism, which reaches about 3B from the centre line and 1.2B down at
// phi = 20 degrees (workflows/strip_footing_cphi.yaml, docs/contact.md).
W = 6;
D = 4;
Include "strip_footing.geo";
