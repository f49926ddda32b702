// One 0.2 m cell across: meshes/slope_3d_slice.geo at Wd = 0.2 m, for the landslide runs at
// 0.2 m cells (docs/landslide.md).  With slip walls on both y faces nothing varies along y,
// so a strip one cell wide solves the same plane-strain problem as the 5 m slope; the strip
// has 25x fewer points (12,450 at 0.2 m with 2x2x2 points per cell instead of 311,250).
Wd = 0.2;
Include "slope_3d_slice.geo";
