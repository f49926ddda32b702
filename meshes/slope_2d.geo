// Slope in plane strain: the cross-section of slope_3d.geo (paper section 4.4, sensitive
// clay).  Height 5 m, 45-degree face, crest plateau 9.95 m long; area
// 5 * 9.95 + 5 * 5 / 2 = 62.25 m^2.  The soil sits on the grid's base (a fixed wall at
// y = 0); leave at least 40 m of floor in front of the toe (x = 14.95) in the grid box.
Hs = 5.0;      // slope height
Lc = 9.95;     // crest plateau length
lc = 1.0;
Point(1) = {0, 0, 0, lc};
Point(2) = {Lc + Hs, 0, 0, lc}; // toe
Point(3) = {Lc, Hs, 0, lc};     // crest edge
Point(4) = {0, Hs, 0, lc};
Line(1) = {1, 2}; // base
Line(2) = {2, 3}; // face
Line(3) = {3, 4}; // crest
Line(4) = {4, 1}; // back
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Physical Surface("soil") = {1};
Physical Curve("base") = {1};
Physical Curve("face") = {2};
Physical Curve("crest") = {3};
Physical Curve("back") = {4};
Physical Point("toe") = {2};
Physical Point("crest_edge") = {3};
