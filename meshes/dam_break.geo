// Dam break (paper Fig. 11, section 4.3; Mast et al.): a water column 4 m long and 2 m high
// at the left of a 6 m long tank.  Only the water is meshed: the tank is the background
// grid's box (e.g. [0, 6] x [0, 3]) with walls on its faces, the gate a removable wall at
// x = 4.
L = 4.0;
H = 2.0;
lc = 0.5;
Point(1) = {0, 0, 0, lc};
Point(2) = {L, 0, 0, lc};
Point(3) = {L, H, 0, lc};
Point(4) = {0, H, 0, lc};
Line(1) = {1, 2}; // tank floor
Line(2) = {2, 3}; // against the gate
Line(3) = {3, 4}; // free surface
Line(4) = {4, 1}; // left wall
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Physical Surface("water") = {1};
Physical Curve("gate_edge") = {2};
Physical Curve("free_surface") = {3};
Physical Point("front") = {2}; // the foot of the column: the surge front starts here
