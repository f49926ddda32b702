#!/usr/bin/env python3
"""Bishop's simplified method of slices, a circular-surface search: the limit-equilibrium
reference for the slopes of docs/error_vs_runtime.md (the factor-of-safety search).

    bench/lem_bishop.py [--water x,h x,h ...] [--gamma-w 9.81]

The slope of workflows/slope_griffiths_lane.yaml (Griffiths & Lane 1999, example 1):
H = 10 m, 2:1, crest 12 m wide behind the top, firm base at the toe's level,
gamma = 20 kN/m^3, c' = 10 kPa, phi' = 20 deg.  With --water, the pore pressure on each
slice's base is gamma_w (h(x) - y) below the piezometric line through the given (x, h)
points.  Prints the lowest factor of safety found and its circle.  Units kN, m."""
import argparse
import math

GROUND = [(0.0, 10.0), (12.0, 10.0), (32.0, 0.0), (45.0, 0.0)]
GAMMA, C, PHI = 20.0, 10.0, math.radians(20.0)


def interp(pts, x):
    if x <= pts[0][0]:
        return pts[0][1]
    for (x0, y0), (x1, y1) in zip(pts, pts[1:]):
        if x <= x1:
            return y0 + (y1 - y0) * (x - x0) / (x1 - x0)
    return pts[-1][1]


def bishop(xc, yc, r, water, gw, nslice=150):
    """F of the circle (xc, yc, r), or None when it does not cut a valid mass."""
    if yc - r < -1e-9:  # the firm base: no circle below it
        return None
    # the arc's extent under the ground surface
    xs = [xc - r + 2 * r * k / 2000 for k in range(2001)]
    inside = [x for x in xs if x >= 0 and yc - math.sqrt(max(r * r - (x - xc) ** 2, 0)) < interp(GROUND, x)]
    if len(inside) < 10:
        return None
    xa, xb = min(inside), max(inside)
    if xa <= 0.0 + 1e-9:  # reaches the back boundary
        return None
    b = (xb - xa) / nslice
    sl = []
    for k in range(nslice):
        x = xa + (k + 0.5) * b
        yb = yc - math.sqrt(max(r * r - (x - xc) ** 2, 0.0))
        ys = interp(GROUND, x)
        if ys <= yb:
            continue
        w = GAMMA * b * (ys - yb)
        sa = (xc - x) / r
        ca = math.sqrt(max(1 - sa * sa, 1e-12))
        u = gw * max(0.0, interp(water, x) - yb) if water else 0.0
        sl.append((w, sa, ca, u))
    drive = sum(w * sa for w, sa, _, _ in sl)
    if drive <= 0:
        return None
    f = 1.5
    for _ in range(100):
        res = sum((C * b + max(w - u * b, 0.0) * math.tan(PHI)) / (ca + sa * math.tan(PHI) / f)
                  for w, sa, ca, u in sl)
        fn = res / drive
        if abs(fn - f) < 1e-6:
            break
        f = fn
    return fn


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--water", nargs="*", default=None)
    ap.add_argument("--gamma-w", type=float, default=9.81)
    a = ap.parse_args()
    water = [tuple(map(float, p.split(","))) for p in a.water] if a.water else None
    best = (1e9, None)
    # coarse grid, then refined around the best centre
    for it, (xr, yr, step) in enumerate([((5, 40), (8, 40), 1.0), (None, None, 0.2), (None, None, 0.05)]):
        if it:
            _, (bx, by, br) = best
            xr, yr = (bx - 5 * step, bx + 5 * step), (by - 5 * step, by + 5 * step)
        nx, ny = int(round((xr[1] - xr[0]) / step)) + 1, int(round((yr[1] - yr[0]) / step)) + 1
        for i in range(nx):
            xc = xr[0] + i * step
            for j in range(ny):
                yc = yr[0] + j * step
                for k in range(1, 41):
                    r = yc * k / 40  # down to tangent with the base
                    f = bishop(xc, yc, r, water, a.gamma_w, 60 if it == 0 else 150)
                    if f is not None and f < best[0]:
                        best = (f, (xc, yc, r))
    f, (xc, yc, r) = best
    print(f"Bishop simplified: F = {f:.3f}, circle centre ({xc:.2f}, {yc:.2f}), radius {r:.2f} m")


if __name__ == "__main__":
    main()
