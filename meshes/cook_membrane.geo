// Cook's membrane (paper Fig. 2; Zhao, Jiang & Choo 2023, section 4.1): a tapered panel
// clamped on its left edge (x = 0, y = 0..44) and sheared on its right edge (x = 48,
// y = 44..60).  Lattice seeding with 2x2 points per 1 m cell (grid lo at the origin) gives
// the paper's 5,776 points; the 32 lattice points lying on the top edge are kept.
lc = 4.0; // element size: the mesh only describes the region, the grid sets the resolution
Point(1) = {0, 0, 0, lc};
Point(2) = {48, 44, 0, lc};
Point(3) = {48, 60, 0, lc};
Point(4) = {0, 44, 0, lc};
Line(1) = {1, 2}; // bottom
Line(2) = {2, 3}; // right: traction edge
Line(3) = {3, 4}; // top
Line(4) = {4, 1}; // left: clamped
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Physical Surface("membrane") = {1};
Physical Curve("clamp") = {4};
Physical Curve("traction_edge") = {2};
Physical Point("tip") = {3};
