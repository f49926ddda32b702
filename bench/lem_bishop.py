#!/usr/bin/env python3
"""Bishop's simplified method of slices with a search over circles: the limit-equilibrium
reference of the factor-of-safety benchmarks (docs/error_vs_runtime.md).

    bench/lem_bishop.py [--ground x,y ...] [--gamma kN/m3] [--c kPa] [--phi deg]
                        [--water x,h ...] [--gamma-w kN/m3] [--back x]

Defaults: the slope of workflows/slope_griffiths_lane.yaml (Griffiths & Lane 1999, ex. 1):
ground (0,10) (12,10) (32,0) (45,0), gamma = 20 kN/m^3, c' = 10 kPa, phi' = 20 deg, the
back boundary at x = 0.  Slopes face +x; the firm base is y = 0 (no circle below it) and
no circle reaches behind the back boundary.  With --water, the pore pressure on a slice's
base is gamma_w (h(x) - y) below the piezometric line through the given (x, h) points
(constant beyond its ends).  With phi = 0 the method is the undrained (Fellenius = Bishop)
circle analysis of Taylor's charts.  Prints the lowest factor of safety and its circle."""
import argparse
import math


def interp(pts, x):
    if x <= pts[0][0]:
        return pts[0][1]
    for (x0, y0), (x1, y1) in zip(pts, pts[1:]):
        if x <= x1:
            return y0 + (y1 - y0) * (x - x0) / (x1 - x0)
    return pts[-1][1]


def crossings(ground, xc, yc, r):
    """x where the lower arc y = yc - sqrt(r^2 - (x - xc)^2) meets the ground polyline."""
    xs = []
    for (x0, y0), (x1, y1) in zip(ground, ground[1:]):
        # points (x0 + t dx, y0 + t dy), t in [0, 1], at distance r from the centre
        dx, dy = x1 - x0, y1 - y0
        fx, fy = x0 - xc, y0 - yc
        a, b, c = dx * dx + dy * dy, 2 * (fx * dx + fy * dy), fx * fx + fy * fy - r * r
        disc = b * b - 4 * a * c
        if disc < 0:
            continue
        for t in ((-b - math.sqrt(disc)) / (2 * a), (-b + math.sqrt(disc)) / (2 * a)):
            if 0 <= t <= 1 and y0 + t * dy <= yc:
                xs.append(x0 + t * dx)
    return sorted(xs)


def bishop(a, xc, yc, r, nslice):
    if yc - r < -1e-9:  # the firm base
        return None
    xs = crossings(a.ground, xc, yc, r)
    if len(xs) < 2:
        return None
    xa, xb = xs[0], xs[-1]
    if xa < a.back or xb - xa < 0.5:
        return None
    tphi = math.tan(math.radians(a.phi))
    b = (xb - xa) / nslice
    sl = []
    for k in range(nslice):
        x = xa + (k + 0.5) * b
        yb = yc - math.sqrt(max(r * r - (x - xc) ** 2, 0.0))
        ys = interp(a.ground, x)
        if ys <= yb:
            return None  # the arc leaves the ground between its ends: not one mass
        sa = (xc - x) / r
        ca = math.sqrt(max(1 - sa * sa, 1e-12))
        u = a.gamma_w * max(0.0, interp(a.water, x) - yb) if a.water else 0.0
        sl.append((a.gamma * b * (ys - yb), sa, ca, u))
    drive = sum(w * sa for w, sa, _, _ in sl)
    if drive <= 0:
        return None
    f = 1.5
    for _ in range(200):
        res = sum((a.c * b + max(w - u * b, 0.0) * tphi) / (ca + sa * tphi / f) for w, sa, ca, u in sl)
        fn = res / drive
        if abs(fn - f) < 1e-7:
            return fn
        f = fn
    return fn


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--ground", nargs="+", default=["0,10", "12,10", "32,0", "45,0"])
    ap.add_argument("--gamma", type=float, default=20.0)
    ap.add_argument("--c", type=float, default=10.0)
    ap.add_argument("--phi", type=float, default=20.0)
    ap.add_argument("--water", nargs="*", default=None)
    ap.add_argument("--gamma-w", type=float, default=9.81)
    ap.add_argument("--back", type=float, default=0.0)
    a = ap.parse_args()
    pts = lambda ps: [tuple(map(float, p.split(","))) for p in ps]
    a.ground = pts(a.ground)
    a.water = pts(a.water) if a.water else None
    hmax = max(y for _, y in a.ground)
    x0, x1 = a.ground[0][0], a.ground[-1][0]
    best = (1e9, None)
    # centres over a grid above the slope, radii from small to tangent with the base; then
    # twice refined around the best circle
    step = (x1 - x0) / 40
    grid = ((x0, x1), (0.5 * hmax, 4 * hmax))
    for it in range(3):
        (xa, xb), (ya, yb) = grid
        nx, ny = int(round((xb - xa) / step)) + 1, int(round((yb - ya) / step)) + 1
        for i in range(nx):
            xc = xa + i * step
            for j in range(ny):
                yc = ya + j * step
                if yc <= 0:
                    continue
                for k in range(1, 61):
                    r = yc * k / 60
                    f = bishop(a, xc, yc, r, 40 if it == 0 else 200)
                    if f is not None and f < best[0]:
                        best = (f, (xc, yc, r))
        if best[1] is None:
            break
        bx, by, _ = best[1]
        grid = ((bx - 4 * step, bx + 4 * step), (by - 4 * step, by + 4 * step))
        step /= 4
    # the best circle again with many slices
    f, (xc, yc, r) = best
    f = bishop(a, xc, yc, r, 1000) or f
    print(f"Bishop simplified: F = {f:.3f}, circle centre ({xc:.2f}, {yc:.2f}), radius {r:.2f} m")


if __name__ == "__main__":
    main()
