// A 0.8 m slice of meshes/slope_3d.geo for the landslide's CI test and resolution sweeps
// (workflows/slope_3d_reduced.yaml, docs/landslide.md).  Same cross-section (height 5 m,
// 45-degree face, crest plateau 9.95 m, toe at x = 14.95 m) extruded 0.8 m across instead
// of 5 m.  With slip walls on both y faces, the soil's container and the loading are
// uniform across y, so the slice and the 5 m slope solve the same plane-strain problem in
// 3D (docs/landslide.md compares the two); the slice has 6.25x fewer points.
// 0.8 m is a whole number of cells at 0.4 m and 0.2 m (and at 0.1 m, 0.16 m, 0.266.. m).
// A file that sets Wd and then includes this one makes another width
// (meshes/slope_3d_strip.geo: one 0.2 m cell across).
Hs = 5.0;      // slope height
Lc = 9.95;     // crest plateau length
If (!Exists(Wd))
  Wd = 0.8;    // width across the slope (the full scene: 5 m)
EndIf
lc = 1.5;
Point(1) = {0, 0, 0, lc};
Point(2) = {Lc + Hs, 0, 0, lc}; // toe
Point(3) = {Lc, 0, Hs, lc};     // crest edge
Point(4) = {0, 0, Hs, lc};
Line(1) = {1, 2}; // base
Line(2) = {2, 3}; // face
Line(3) = {3, 4}; // crest
Line(4) = {4, 1}; // back
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
out[] = Extrude {0, Wd, 0} { Surface{1}; };
// out[0]: the face at y = Wd, out[1]: the volume, out[2..5]: the surfaces swept by lines 1-4
Physical Volume("soil") = {out[1]};
Physical Surface("base") = {out[2]};
Physical Surface("face") = {out[3]};
Physical Surface("crest") = {out[4]};
Physical Surface("back") = {out[5]};
Physical Surface("side_y0") = {1};
Physical Surface("side_y1") = {out[0]};
Physical Point("toe") = {2};
