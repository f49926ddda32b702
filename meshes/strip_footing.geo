// Strip footing (paper Fig. 7, section 4.2; workflows/strip_footing.yaml and
// strip_footing_cphi.yaml seed the physical surface "soil" on the grid's lattice): the right
// half of the problem, a W x D soil block with B = 1.  The rigid footing (half width B/2)
// rests on the top edge from x = 0 to 0.5; the symmetry plane is x = 0.
// The paper's block is 12B x 12B.  A file that sets W and D and then includes this one
// makes a smaller block (strip_footing_3b.geo for the CTests, strip_footing_4b.geo and
// strip_footing_6x4b.geo for the measurements at h = B/20; docs/contact.md).  Lattice
// seeding puts points at the cell-centred sub-lattice positions inside the surface, so a
// block whose sides are whole numbers of cells gets the same points as a box.
B = 1.0;
If (!Exists(W))
  W = 12 * B; // block width (half model)
EndIf
If (!Exists(D))
  D = 12 * B; // block depth
EndIf
lc = 0.5;
Point(1) = {0, 0, 0, lc};
Point(2) = {W, 0, 0, lc};
Point(3) = {W, D, 0, lc};
Point(4) = {B / 2, D, 0, lc / 4};
Point(5) = {0, D, 0, lc / 4};
Line(1) = {1, 2}; // base
Line(2) = {2, 3}; // far side
Line(3) = {3, 4}; // free surface
Line(4) = {4, 5}; // under the footing
Line(5) = {5, 1}; // symmetry plane
Curve Loop(1) = {1, 2, 3, 4, 5};
Plane Surface(1) = {1};
Physical Surface("soil") = {1};
Physical Curve("footing_edge") = {4};
Physical Curve("surface") = {3};
Physical Curve("symmetry") = {5};
Physical Curve("base") = {1};
Physical Curve("far_side") = {2};
Physical Point("footing_corner") = {4};
