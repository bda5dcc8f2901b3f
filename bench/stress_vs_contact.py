#!/usr/bin/env python3
"""Stresses below a frictionless Hertz contact against Hamilton's closed
form (1983, normal part), for mpcontact's x-z slice and, optionally,
CONTACT's x-z plane (docs/performance.md, "Stresses below the surface").

usage: stress_vs_contact.py MPCONTACT_SOLVE_OUT [CONTACT_NAME.subs]
(R = 18 mm, Fe, P = 20 N as in ../shared/peers/contact/gen_subs.py)
"""
import json
import math
import sys

import numpy as np

d = sys.argv[1]
cj = json.load(open(f"{d}/case.json"))
n = cj["grid_points"]; h = cj["spacing_m"]
E, nu, R, P = 210e9, 0.3, 18e-3, 20.0
a = (3*P*R/(4*E/(1-nu**2)))**(1/3); p0 = 3*P/(2*math.pi*a*a)
zs = np.array(cj["stress"]["slice_depths_m"])
comps = ["sxx","syy","szz","syz","sxz","sxy"]
S = {c: np.load(f"{d}/stress/slice_along_{c}.npy") for c in comps}
def ham(x, y, z):
    r2 = x*x+y*y; A = r2+z*z-1; s = math.sqrt(A*A+4*z*z)
    m = math.sqrt(max(0.5*(s+A),0)); nn = math.sqrt(max(0.5*(s-A),0))
    phi = math.atan(1/m) if m > 0 else math.pi/2
    g = m*m-nn*nn+z*m-nn; hh = 2*m*nn+m+z*nn
    com = (1-nu)*nn*z*z-(1-2*nu)/3*(nn*s+2*A*nn+1)-nu*m*z
    mzs = m*z/s if s > 0 else 0
    sxx = (1+nu)*z*phi+((y*y-x*x)/r2*com-nn*(x*x+2*nu*y*y)-x*x*mzs)/r2
    syy = (1+nu)*z*phi+((x*x-y*y)/r2*com-nn*(y*y+2*nu*x*x)-y*y*mzs)/r2
    szz = -nn+mzs
    sh = lambda c: 0 if z == 0 else -z*(c*nn/s-c*z*hh/(g*g+hh*hh))
    r4 = r2*r2
    sxy = x*y*(1-2*nu)/r4*(-nn*r2+2/3*nn*(s+2*A)-z*(z*nn+m)+2/3) + (x*y*z/r4*(-m*r2/s-z*nn+m) if z > 0 else 0)
    return [sxx, syy, szz, sh(y), sh(x), sxy]
# row of the slice: the centroid row
iy = int(round(json.load(open(f"{d}/case.json"))["stress"]["slice_through_m"][1] / h + (n-1)/2))
y = (iy-(n-1)/2)*h/a
worst = 0; worst_z = {}
for k, z in enumerate(zs):
    for ix in range(n):
        x = (ix-(n-1)/2)*h/a
        if abs(x) > 1.5: continue
        w = ham(x, y, z/a)
        e = max(abs(S[c][k, ix]/p0 - w[i]) for i, c in enumerate(comps))
        worst = max(worst, e); worst_z[k] = max(worst_z.get(k, 0), e)
print(f"a = {a*1e6:.3f} um, p0 = {p0/1e6:.1f} MPa; worst over the slice {worst:.2e} p0")
for k in [0, 1, 2, 4, 8, 16, 38, 60, 120]:
    print(f"  z = {zs[k]/a:.4f} a: {worst_z[k]:.2e}")

# CONTACT's blocks: axis (31 points), then the x-z plane (121 x 121); mm, N/mm² (MPa), compression negative.
if len(sys.argv) > 2:
    rows, skip = [], False
    for line in open(sys.argv[2]):
        t = line.split()
        if not t:
            continue
        if t[0].startswith('%'):
            # the line after a '% NX NY NZ' comment holds a block's sizes
            skip = "NX" in t
            continue
        if skip:
            skip = False
            continue
        rows.append([float(x) for x in t])
    worst = 0; cnt = 0; wz = {}
    for v in rows[31:]:
        x, y, z = v[0]/(a*1e3), v[1]/(a*1e3), v[2]/(a*1e3)
        if x == 0 and y == 0:
            continue
        sxx, sxy, sxz, syy, syz, szz = v[8], v[9], v[10], v[11], v[12], v[13]
        w = ham(x, y, z)
        got = [sxx, syy, szz, syz, sxz, sxy]
        e = max(abs(got[i]/(p0/1e6) - w[i]) for i in range(6))
        worst = max(worst, e); cnt += 1
        zk = round(z, 4); wz[zk] = max(wz.get(zk, 0), e)
    print(f"CONTACT x-z plane: {cnt} points, worst {worst:.2e} p0")
    for zk in sorted(wz)[::15]:
        print(f"  z = {zk:.4f} a: {wz[zk]:.2e}")
