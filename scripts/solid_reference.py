#!/usr/bin/env python3
"""Independent 3-D solid finite-element reference for the spot-welded friction bar.

Pure continuum model: quadratic hexahedra (20-node serendipity by default, 27-node
Lagrange with --elem 27), full 3x3x3 Gauss integration, consistent mass, isotropic
linear elasticity.  No shell, beam or connector elements anywhere.

Geometry (mm, N, t, s):
  sheet A  x in [0,125],  z in [0,25], y in [-0.25, 0.25]
  sheet B  x in [40,165], z in [0,25], y in [ 0.25, 0.75]
  the sheets touch on y = 0.25 over x in [40,125]; the interface nodes are
  duplicated (no connection; contact only with --contact-per-area) except inside two weld discs of
  diameter 5 at (x,z) = (60,12.5) and (105,12.5), where the solid is continuous.
  sheet A: face x = 0 clamped.  sheet B: face x = 165 rigidly tied to a 6-DOF
  master node at (165, 0.5, 12.5) (exact elimination, u_s = u_m + th x (x_s - x_m)).

In-plane mesh: a multi-block structured quadratic mesh (9-point lattice per quad,
extruded through each sheet's thickness with nt elements per sheet).  Each weld
sits in a square box meshed as an O-grid (core square + inner ring inside the
disc, graded outer ring from the circle to the box), so the disc boundary is a
mesh line with all its nodes (mid-side nodes too) exactly on the circle.
Default (--grade 8): 12.5 x 12.5 weld boxes with nz elements per side (circle
in 4 nz arcs) inside a tensor-product grid of strips whose element size is
25/nz in the interior and (25/nz)/8 at every physical edge (free edges z = 0, 25,
sheet ends x = 40, 125, clamp x = 0, tie x = 165), growth ratio 1.4: this
resolves the 3-D edge boundary layers (width ~ t) which otherwise make the
torsional stiffness converge slowly.  --grade 1: uniform strips and 25 x 25
weld boxes (kept for comparison).

Usage:
  python3 scripts/solid_reference.py --case friction_bar --refine 1,2,3,4 --out fb.json
  python3 scripts/solid_reference.py --case friction_bar --refine 2,2,2 --nt 2,3,4 --out fb_nt.json
  python3 scripts/solid_reference.py --case strip --refine 1,2,3,4 --out strip.json
  python3 scripts/solid_reference.py --case friction_bar --refine 0,1,2 --contact-per-area 160 --modes 2 --out fbc.json
  (--welds none: sheets not bonded, fixed-interface problem only;
   --elem 27: 27-node Lagrange bricks instead of 20-node serendipity;
   --contact-per-area KAPPA: the statics under Fy & Mx once more with frictionless penalty
   contact p = KAPPA max(0, -g) on the sheets' interface outside the welds, integrated at the
   3 x 3 Gauss points of its faces -- the surface-to-surface penalty of a node-matching
   interface -- by active-set iteration; resultant, contact area, peak pressure, penetration)

refine N -> nz = 4 (N + 1): nominal in-plane element size 25/nz.  nt (elements
through each sheet's thickness) defaults to 2.  Several levels in one call give
level-to-level differences and a Richardson estimate (error ~ C h^p, last 3 levels).
Checks printed and stored: K symmetry, K times the 6 rigid motions of the free
body, total mass = rho V, eigen-residuals, tie kinematics, bonded area = 2 pi r^2.

Solver: scikit-sparse CHOLMOD if importable, else scipy SuperLU (symmetric mode); with
CHOLMOD the contact's active-set changes of up to 500 points are rank updates of the
factor.  On Debian bookworm (SuiteSparse 5): apt install libsuitesparse-dev, then in a
venv pip install 'numpy<2' 'scipy<1.14' 'cython<3' setuptools wheel and
pip install --no-build-isolation scikit-sparse==0.4.12.
"""

import argparse
import gc
import json
import math
import resource
import sys
import time

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

E_MOD = 210000.0
NU = 0.3
RHO = 7.85e-9

WIDTH = 25.0
T_SHEET = 0.5
WELD_R = 2.5
WELDS_X = (60.0, 105.0)
WELD_Z = 12.5
MASTER = np.array([165.0, 0.5, 12.5])
FY = -0.7
MX = -20.0

T0 = time.time()


def rss_gb():
    try:
        with open('/proc/self/statm') as fh:
            return int(fh.read().split()[1]) * resource.getpagesize() / 1024.0 ** 3
    except OSError:
        return float('nan')


def log(msg):
    print(f"[{time.time() - T0:8.1f} s {rss_gb():5.2f} GB] {msg}", flush=True)


def peak_mem_gb():
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0 / 1024.0


# ----------------------------------------------------------------------------
# element shape functions (built from a monomial basis, so both the 20-node
# serendipity and the 27-node Lagrange element come from one routine)
# ----------------------------------------------------------------------------

def hex_local_nodes(nnode):
    """Local lattice offsets (a,b,c) in {0,1,2}^3 of the element nodes."""
    maxmid = 1 if nnode == 20 else 3
    loc = [(a, b, c) for c in range(3) for b in range(3) for a in range(3)
           if sum(v == 1 for v in (a, b, c)) <= maxmid]
    loc = np.array(loc, dtype=np.int64)
    assert len(loc) == nnode
    return loc


def hex_monomials(nnode):
    """Exponent triples spanning the element's polynomial space."""
    exps = [(i, j, k) for k in range(3) for j in range(3) for i in range(3)]
    if nnode == 20:  # serendipity: at most one exponent equal to 2
        exps = [e for e in exps if sum(v == 2 for v in e) <= 1]
    exps = np.array(exps, dtype=np.int64)
    assert len(exps) == nnode
    return exps


class HexElement:
    def __init__(self, nnode):
        self.nnode = nnode
        self.loc = hex_local_nodes(nnode)
        self.xi_nodes = (self.loc - 1).astype(float)
        self.exps = hex_monomials(nnode)
        V = self._mono(self.xi_nodes)
        self.C = np.linalg.inv(V)  # N(xi) = mono(xi) @ C
        g = math.sqrt(0.6)
        pts1 = np.array([-g, 0.0, g])
        w1 = np.array([5.0, 8.0, 5.0]) / 9.0
        P = np.array([(a, b, c) for c in pts1 for b in pts1 for a in pts1])
        W = np.array([wa * wb * wc for wc in w1 for wb in w1 for wa in w1])
        self.gp, self.gw = P, W
        self.N = self._mono(P) @ self.C                     # (ng, nn)
        self.dN = np.stack([self._dmono(P, d) @ self.C for d in range(3)], axis=1)  # (ng,3,nn)
        # self-checks of the shape functions
        assert np.allclose(self._mono(self.xi_nodes) @ self.C, np.eye(nnode), atol=1e-12)
        assert np.allclose(self.N.sum(1), 1.0, atol=1e-12)
        assert np.allclose(self.dN.sum(2), 0.0, atol=1e-12)

    def _mono(self, P):
        e = self.exps
        return (P[:, None, 0] ** e[None, :, 0]) * (P[:, None, 1] ** e[None, :, 1]) * \
               (P[:, None, 2] ** e[None, :, 2])

    def _dmono(self, P, d):
        e = self.exps.copy()
        coef = e[:, d].astype(float)
        e[:, d] = np.maximum(e[:, d] - 1, 0)
        val = (P[:, None, 0] ** e[None, :, 0]) * (P[:, None, 1] ** e[None, :, 1]) * \
              (P[:, None, 2] ** e[None, :, 2])
        return val * coef[None, :]


def elasticity_matrix(E, nu):
    lam = E * nu / ((1 + nu) * (1 - 2 * nu))
    mu = E / (2 * (1 + nu))
    D = np.zeros((6, 6))
    D[:3, :3] = lam
    D[np.arange(3), np.arange(3)] += 2 * mu
    D[3, 3] = D[4, 4] = D[5, 5] = mu
    return D


def element_batch(el, X, D, rho):
    """Stiffness (ne,3nn,3nn) and scalar mass (ne,nn,nn) for a batch of elements.
    X: (ne, nn, 3) nodal coordinates.  Strain order xx,yy,zz,xy,yz,zx."""
    ne, nn, _ = X.shape
    ng = len(el.gw)
    J = np.einsum('gin,enj->egij', el.dN, X, optimize=True)       # J_ij = dx_j/dxi_i
    detJ = np.linalg.det(J)
    invJ = np.linalg.inv(J)
    G = np.einsum('egij,gjn->egin', invJ, el.dN, optimize=True)   # dN/dx_i
    B = np.zeros((ne, ng, 6, 3 * nn))
    Gx, Gy, Gz = G[:, :, 0, :], G[:, :, 1, :], G[:, :, 2, :]
    B[:, :, 0, 0::3] = Gx
    B[:, :, 1, 1::3] = Gy
    B[:, :, 2, 2::3] = Gz
    B[:, :, 3, 0::3] = Gy
    B[:, :, 3, 1::3] = Gx
    B[:, :, 4, 1::3] = Gz
    B[:, :, 4, 2::3] = Gy
    B[:, :, 5, 0::3] = Gz
    B[:, :, 5, 2::3] = Gx
    wdet = el.gw[None, :] * np.abs(detJ)
    DB = np.einsum('ij,egjk->egik', D, B, optimize=True) * wdet[:, :, None, None]
    Bm = B.reshape(ne, ng * 6, 3 * nn)
    DBm = DB.reshape(ne, ng * 6, 3 * nn)
    Ke = np.matmul(Bm.transpose(0, 2, 1), DBm)
    Me = np.einsum('eg,ga,gb->eab', rho * wdet, el.N, el.N, optimize=True)
    return Ke, Me, detJ


# ----------------------------------------------------------------------------
# 2-D multi-block quadratic mesh
# ----------------------------------------------------------------------------

def lattice1d(b):
    """Element boundary coordinates -> quadratic lattice (boundaries + midpoints)."""
    b = np.asarray(b, float)
    out = np.empty(2 * len(b) - 1)
    out[0::2] = b
    out[1::2] = 0.5 * (b[:-1] + b[1:])
    return out


def geometric01(n, ratio):
    """n intervals on [0,1] with last/first size = ratio (geometric)."""
    if n == 1 or abs(ratio - 1.0) < 1e-12:
        return np.linspace(0.0, 1.0, n + 1)
    q = ratio ** (1.0 / (n - 1))
    d = q ** np.arange(n)
    b = np.concatenate([[0.0], np.cumsum(d)])
    return b / b[-1]


def graded(L, h0, hmid, h1, q):
    """Element boundaries on [0, L]: sizes start at h0, grow geometrically (ratio q)
    to hmid, and shrink again to h1 at the far end; the count is chosen so that
    the sum is closest to L and the sizes are then scaled to fit exactly."""
    if h0 >= hmid and h1 >= hmid:
        n = max(1, int(round(L / hmid)))
        return np.linspace(0.0, L, n + 1)
    best = None
    for n in range(1, 100000):
        i = np.arange(n)
        sz = np.minimum(np.minimum(h0 * q ** i, h1 * q ** (n - 1 - i)), hmid)
        tot = sz.sum()
        if best is None or abs(tot - L) < abs(best[1] - L):
            best = (sz, tot)
        if tot > L:
            break
    sz = best[0] * (L / best[1])
    return np.concatenate([[0.0], np.cumsum(sz)])


def strip_block(xbreaks, zbreaks):
    xs = lattice1d(xbreaks)
    zs = lattice1d(zbreaks)
    P = np.stack(np.meshgrid(xs, zs, indexing='ij'), axis=-1)
    return P


def ogrid_blocks(cx, cz, W, r, side01, a_ratio=0.5, grading=None):
    """O-grid of the box [cx-W,cx+W] x [cz-W,cz+W] around a circle of radius r.
    side01: element boundaries (in [0,1]) along each box side (n = len - 1 elements);
    grading: None (outer ring geometric from the circle size to the box size) or
    (h_mid, h_edge, q) for a ring graded fine at the circle and at the box.
    Returns list of (P, bonded, kind) and a parameter dict."""
    n = len(side01) - 1
    a = a_ratio * r
    hc = (0.5 * math.pi * r) / n          # tangential size on the circle
    hb = 2.0 * W / n                      # mean tangential size on the box
    L = W - r
    if grading is None:
        if L > hb:
            q = (L - hc) / (L - hb)
            n2 = max(1, int(round(1 + math.log(hb / hc) / math.log(q))))
        else:
            n2 = max(1, int(round(L / hc)))
        t_out = lattice1d(geometric01(n2, hb / hc))
    else:
        hmid, hedge, qg = grading
        tb = graded(L, hc, hmid, hedge, qg) / L
        n2 = len(tb) - 1
        t_out = lattice1d(tb)
    n1 = max(1, int(round((r - a) / (0.5 * (hc + 2 * a / n)))))
    s_lat = lattice1d(np.linspace(0.0, 1.0, n + 1))
    s_side = lattice1d(np.asarray(side01, float))
    t_in = lattice1d(np.linspace(0.0, 1.0, n1 + 1))
    c = np.array([cx, cz])
    blocks = []
    for q_ in range(4):
        th0 = -0.25 * math.pi + 0.5 * math.pi * q_
        th1 = th0 + 0.5 * math.pi
        th = th0 + 0.5 * math.pi * s_lat
        circ = c[None, :] + r * np.stack([np.cos(th), np.sin(th)], axis=1)

        def sq(A):
            C0 = c + A * math.sqrt(2.0) * np.array([math.cos(th0), math.sin(th0)])
            C1 = c + A * math.sqrt(2.0) * np.array([math.cos(th1), math.sin(th1)])
            return C0[None, :] + sl[:, None] * (C1 - C0)[None, :]

        sl = s_side
        sqW = sq(W)
        sl = s_lat
        sqa = sq(a)
        Pout = (1 - t_out)[None, :, None] * circ[:, None, :] + t_out[None, :, None] * sqW[:, None, :]
        Pin = (1 - t_in)[None, :, None] * sqa[:, None, :] + t_in[None, :, None] * circ[:, None, :]
        blocks.append((Pout, False, 'weld_outer_ring'))
        blocks.append((Pin, True, 'weld_inner_ring'))
    core1 = -a + 2 * a * s_lat
    Pc = np.stack(np.meshgrid(cx + core1, cz + core1, indexing='ij'), axis=-1)
    blocks.append((Pc, True, 'weld_core'))
    info = dict(box_half_width=W, radius=r, core_half_width=a, n_tangential_per_side=n,
                n_radial_inner=n1, n_radial_outer=n2, outer_grading_ratio=hb / hc,
                circle_arcs=4 * n, outer_ring_sizes_t=np.diff(t_out[0::2]).round(5).tolist())
    return blocks, info


def build_2d(case, nz, grade=1.0, q=1.4, box_half=None):
    """Multi-block quadratic lattice of the mid-plane.

    grade = 1: uniform strips; each weld in a full-width 25 x 25 O-grid box whose
      sides have nz elements.
    grade > 1: element size (25/nz)/grade at all physical edges (free edges z = 0, 25,
      sheet ends x = 40, 125, clamp x = 0, tie x = 165), growing by ratio q to 25/nz
      inside (resolves the 3-D edge boundary layers of width ~ t); each weld in an
      O-grid box of half-width box_half (default 6.25) with nz elements per side,
      embedded in a tensor-product grid of graded strips."""
    h = WIDTH / nz
    he = h / grade
    blocks = []
    info = {'nz': nz, 'h_nominal': h,
            'edge_grading': dict(h_edge=he, ratio=q) if grade > 1 else None}
    if case == 'friction_bar':
        Wb = box_half if box_half is not None else (0.5 * WIDTH if grade <= 1 else 6.25)
        full = Wb >= 0.5 * WIDTH - 1e-9
        if full:
            Wb = 0.5 * WIDTH
            zb = graded(WIDTH, he, h, he, q)
            box_side = zb / WIDTH
            zints = [zb]
            hbx = h
            ograding = (h, he, q) if grade > 1 else None
        else:
            nb = nz
            hbx = 2 * Wb / nb
            box_side = np.linspace(0.0, 1.0, nb + 1)
            z1, z2 = WELD_Z - Wb, WELD_Z + Wb
            zints = [graded(z1, he, h, hbx, q), z1 + 2 * Wb * box_side,
                     z2 + graded(WIDTH - z2, hbx, h, he, q)]
            ograding = (hbx, hbx, q)
        info['box_half_width'] = Wb
        info['n_across_width'] = int(sum(len(z) - 1 for z in zints))
        boxes = [(wx - Wb, wx + Wb, wx) for wx in WELDS_X]
        xb = [0.0, 40.0]
        for bx in boxes:
            xb += [bx[0], bx[1]]
        xb += [125.0, 165.0]
        physical = (0.0, 40.0, 125.0, 165.0)
        strips = []
        for x0, x1 in zip(xb[:-1], xb[1:]):
            box = [bx for bx in boxes if abs(bx[0] - x0) < 1e-12]
            if box:
                xd = x0 + 2 * Wb * box_side
            else:
                h0 = he if any(abs(x0 - p) < 1e-9 for p in physical) else (hbx if grade > 1 else h)
                h1 = he if any(abs(x1 - p) < 1e-9 for p in physical) else (hbx if grade > 1 else h)
                xd = x0 + graded(x1 - x0, h0, h, h1, q)
                strips.append([x0, x1, len(xd) - 1])
            for iz, zd in enumerate(zints):
                if box and (full or iz == 1):
                    bl, oinfo = ogrid_blocks(box[0][2], WELD_Z, Wb, WELD_R, box_side,
                                             grading=ograding)
                    blocks += bl
                    info['ogrid'] = oinfo
                else:
                    blocks.append((strip_block(xd, zd), False, 'strip'))
        info['strips_x_elements'] = strips
    elif case == 'strip':
        zb = graded(WIDTH, he, h, he, q)
        xbr = graded(165.0, he, h, he, q)
        blocks.append((strip_block(xbr, zb), False, 'strip'))
        info['strips_x_elements'] = [[0.0, 165.0, len(xbr) - 1]]
        info['n_across_width'] = len(zb) - 1
    else:
        raise ValueError(case)

    # merge coincident lattice points of all blocks
    pts, elems, bonded_el, kinds = [], [], [], []
    off = 0
    for P, bonded, kind in blocks:
        I, J = P.shape[0], P.shape[1]
        assert I % 2 == 1 and J % 2 == 1
        ids = off + np.arange(I * J).reshape(I, J)
        pts.append(P.reshape(-1, 2))
        for ei in range((I - 1) // 2):
            for ej in range((J - 1) // 2):
                elems.append(ids[2 * ei:2 * ei + 3, 2 * ej:2 * ej + 3])
                bonded_el.append(bonded)
                kinds.append(kind)
        off += I * J
    pts = np.concatenate(pts)
    tree = cKDTree(pts)
    pairs = tree.query_pairs(1e-7, output_type='ndarray')
    g = sp.coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(len(pts), len(pts)))
    ncomp, lab = connected_components(g, directed=False)
    first = np.full(ncomp, -1)
    order = np.arange(len(pts))[::-1]
    first[lab[order]] = order  # smallest index of each component
    P2 = pts[first]
    E2 = lab[np.array(elems)]  # (ne2, 3, 3) merged ids
    # sanity: no element may have coincident nodes
    assert all(len(np.unique(e)) == 9 for e in E2.reshape(len(E2), 9))
    info['n_2d_elements'] = len(E2)
    info['n_2d_lattice_points'] = len(P2)
    kinds = np.array(kinds)
    info['n_2d_elements_by_kind'] = {k: int((kinds == k).sum()) for k in np.unique(kinds)}
    return P2, E2, np.array(bonded_el), kinds, info


def area_2d(P2, E2, mask):
    """Area of the 2-D quadratic (9-node Lagrange) elements selected by mask (3x3 Gauss)."""
    g = math.sqrt(0.6)
    p1 = np.array([-g, 0, g])
    w1 = np.array([5, 8, 5]) / 9.0
    def l(x):
        return np.array([0.5 * x * (x - 1), 1 - x * x, 0.5 * x * (x + 1)])
    def dl(x):
        return np.array([x - 0.5, -2 * x, x + 0.5])
    A = 0.0
    X = P2[E2[mask]]  # (ne,3,3,2)
    for i, xi in enumerate(p1):
        for j, et in enumerate(p1):
            dxi = np.einsum('a,b,eabk->ek', dl(xi), l(et), X)
            det_ = np.einsum('a,b,eabk->ek', l(xi), dl(et), X)
            A += w1[i] * w1[j] * np.abs(dxi[:, 0] * det_[:, 1] - dxi[:, 1] * det_[:, 0]).sum()
    return A


# ----------------------------------------------------------------------------
# 3-D mesh (extrusion through each sheet's thickness)
# ----------------------------------------------------------------------------

def build_3d(case, nz, nt, nnode, welds='area', grade=1.0):
    P2, E2, bonded_el, kinds, info = build_2d(case, nz, grade)
    NP = len(P2)
    L = 2 * nt + 1
    el = HexElement(nnode)
    loc = el.loc
    cx = P2[E2[:, 1, 1], 0]
    if case == 'friction_bar':
        sheets = [(0, cx < 125.0, -0.25), (1, cx > 40.0, 0.25)]
    else:
        sheets = [(0, np.ones(len(E2), bool), -0.25)]
    codes, esheet = [], []
    for s, mask, y0 in sheets:
        Es = E2[mask]
        P = Es[:, loc[:, 0], loc[:, 1]]  # (ne, nn)
        for layer in range(nt):
            K = 2 * layer + loc[:, 2]
            codes.append((s * NP + P) * L + K[None, :])
            esheet.append(np.full(len(Es), s))
    C = np.concatenate(codes)
    esheet = np.concatenate(esheet)
    bonded_pts = np.zeros(NP, bool)
    if case == 'friction_bar' and welds == 'area':
        bonded_pts[np.unique(E2[bonded_el])] = True
        s_ = C // (NP * L)
        p_ = (C // L) % NP
        k_ = C % L
        repl = (s_ == 1) & (k_ == 0) & bonded_pts[p_]
        C = np.where(repl, p_ * L + (L - 1), C)
    uniq, inv = np.unique(C, return_inverse=True)
    conn = inv.reshape(C.shape)
    s_n = uniq // (NP * L)
    p_n = (uniq // L) % NP
    k_n = uniq % L
    y_base = np.array([-0.25, 0.25])[s_n]
    X = np.stack([P2[p_n, 0], y_base + T_SHEET * k_n / (L - 1), P2[p_n, 1]], axis=1)
    info.update(dict(nt=nt, element=f'hex{nnode}', n_elements=int(len(conn)),
                     n_nodes=int(len(X)), n_dof=int(3 * len(X)),
                     n_bonded_interface_nodes=int(bonded_pts.sum()) if welds == 'area' else 0))
    iface = None
    if case == 'friction_bar':
        # bonded area (the 2-D quadratic elements inside the discs)
        A = area_2d(P2, E2, bonded_el)
        info['bonded_area_mm2'] = A
        info['bonded_area_exact_2_pi_r2'] = 2 * math.pi * WELD_R ** 2
        iface = interface_faces(P2, E2, bonded_el, bonded_pts, NP, L, uniq, nnode)
    return el, X, conn, esheet, s_n, info, iface


def interface_faces(P2, E2, bonded_el, bonded_pts, NP, L, uniq, nnode):
    """The sheets' contact interface y = 0.25 over the overlap 40 < x < 125, outside the
    weld discs: for every 2-D element there, its face nodes on sheet A's top layer and on
    sheet B's bottom layer (one node where the disc's rim makes the solid continuous), the
    face's shape functions (8-node serendipity for hex20, 9-node Lagrange for hex27) and a
    3 x 3 Gauss rule.  Returns the gap operator's pieces: for each Gauss point, the nodes
    and weights of g = u_y(B) - u_y(A), and its area weight w |J|."""
    cx = P2[E2[:, 1, 1], 0]
    mask = (cx > 40.0) & (cx < 125.0) & ~bonded_el
    E = E2[mask]
    loc2 = [(a, b) for b in range(3) for a in range(3) if nnode == 27 or (a, b) != (1, 1)]
    loc2 = np.array(loc2, dtype=np.int64)
    exps = [(i, j) for j in range(3) for i in range(3) if nnode == 27 or (i, j) != (2, 2)]
    exps = np.array(exps, dtype=np.int64)
    xi_n = (loc2 - 1).astype(float)

    def mono(P, dx=0, dz=0):
        e = exps.copy()
        c = np.ones(len(e))
        for d, k in ((0, dx), (1, dz)):
            for _ in range(k):
                c = c * e[:, d]
                e[:, d] = np.maximum(e[:, d] - 1, 0)
        return c[None, :] * P[:, None, 0] ** e[None, :, 0] * P[:, None, 1] ** e[None, :, 1]

    C = np.linalg.inv(mono(xi_n))
    g = math.sqrt(0.6)
    p1, w1 = np.array([-g, 0.0, g]), np.array([5.0, 8.0, 5.0]) / 9.0
    gp = np.array([(a, b) for b in p1 for a in p1])
    gw = np.array([wa * wb for wb in w1 for wa in w1])
    N = mono(gp) @ C
    dNa, dNb = mono(gp, dx=1) @ C, mono(gp, dz=1) @ C
    assert np.allclose(mono(xi_n) @ C, np.eye(len(loc2)), atol=1e-12)
    pts = E[:, loc2[:, 0], loc2[:, 1]]                       # (ne, nn) lattice points
    Xf = P2[pts]                                            # (ne, nn, 2): (x, z)
    ja = np.einsum('gn,enk->egk', dNa, Xf)
    jb = np.einsum('gn,enk->egk', dNb, Xf)
    detJ = np.abs(ja[:, :, 0] * jb[:, :, 1] - ja[:, :, 1] * jb[:, :, 0])
    code_a = pts * L + (L - 1)
    code_b = np.where(bonded_pts[pts], code_a, (NP + pts) * L)
    node_a, node_b = np.searchsorted(uniq, code_a), np.searchsorted(uniq, code_b)
    assert np.all(uniq[node_a] == code_a) and np.all(uniq[node_b] == code_b)
    return dict(node_a=node_a, node_b=node_b, N=N, wJ=gw[None, :] * detJ,
                xz=np.einsum('gn,enk->egk', N, Xf), area=float((gw[None, :] * detJ).sum()),
                n_faces=int(len(E)))


# ----------------------------------------------------------------------------
# assembly
# ----------------------------------------------------------------------------

class _Accumulator:
    """Sums sparse matrices with a binary-counter merge (bounded memory and work)."""

    def __init__(self):
        self.stack = []

    def add(self, A):
        lvl = 0
        while self.stack and self.stack[-1][1] == lvl:
            B, _ = self.stack.pop()
            A = A + B
            lvl += 1
        self.stack.append((A, lvl))

    def total(self):
        A = None
        while self.stack:
            B, _ = self.stack.pop()
            A = B if A is None else A + B
        return A


def assemble(el, X, conn, batch=1000):
    """Global stiffness K (3n x 3n) and scalar (per-node) consistent mass m (n x n);
    the full mass matrix is M = m (x) I3."""
    D = elasticity_matrix(E_MOD, NU)
    nn = el.nnode
    nnodes = len(X)
    ndof = 3 * nnodes
    itype = np.int32 if ndof < 2 ** 31 - 1 else np.int64
    Kacc, Macc = _Accumulator(), _Accumulator()
    detmin, detmax, bad = np.inf, 0.0, 0
    ratio_min = np.inf
    for b0 in range(0, len(conn), batch):
        c = conn[b0:b0 + batch]
        Ke, Me, detJ = element_batch(el, X[c], D, RHO)
        sgn = np.sign(detJ)
        bad += int(np.sum(np.any(sgn != sgn[:, :1], axis=1)))
        ad = np.abs(detJ)
        detmin = min(detmin, ad.min())
        detmax = max(detmax, ad.max())
        ratio_min = min(ratio_min, (ad.min(1) / ad.max(1)).min())
        dofs = (3 * c[:, :, None] + np.arange(3)[None, None, :]).reshape(len(c), 3 * nn).astype(itype)
        rows = np.repeat(dofs, 3 * nn, axis=1).ravel()
        cols = np.tile(dofs, (1, 3 * nn)).ravel()
        Kacc.add(sp.coo_matrix((Ke.ravel(), (rows, cols)), shape=(ndof, ndof)).tocsr())
        del Ke, rows, cols
        ci = c.astype(itype)
        rows = np.repeat(ci, nn, axis=1).ravel()
        cols = np.tile(ci, (1, nn)).ravel()
        Macc.add(sp.coo_matrix((Me.ravel(), (rows, cols)), shape=(nnodes, nnodes)).tocsr())
    K = Kacc.total()
    m = Macc.total()
    quality = dict(detJ_min=float(detmin), detJ_max=float(detmax),
                   elements_with_detJ_sign_change=bad,
                   min_ratio_detJ_within_element=float(ratio_min))
    return K, m, quality


def mass_full(m):
    return sp.kron(m, sp.identity(3, format='csr'), format='csr')


def rigid_modes(X, center=np.zeros(3)):
    n = len(X)
    R = np.zeros((3 * n, 6))
    d = X - center
    for c in range(3):
        R[c::3, c] = 1.0
    # rotation about x: (0, -dz, dy); about y: (dz, 0, -dx); about z: (-dy, dx, 0)
    R[1::3, 3] = -d[:, 2]
    R[2::3, 3] = d[:, 1]
    R[0::3, 4] = d[:, 2]
    R[2::3, 4] = -d[:, 0]
    R[0::3, 5] = -d[:, 1]
    R[1::3, 5] = d[:, 0]
    return R


# ----------------------------------------------------------------------------
# solvers
# ----------------------------------------------------------------------------

class Factor:
    """Sparse symmetric positive-definite factorisation (CHOLMOD if available, else
    SuperLU in symmetric mode).  No self-referencing closures, so 'del' frees it."""

    def __init__(self, A):
        A = A.tocsc()
        self.n = A.shape[0]
        try:
            from sksparse.cholmod import cholesky
            self.F = cholesky(A)
            self.kind = 'cholmod'
        except ImportError:
            self.F = spla.splu(A, permc_spec='MMD_AT_PLUS_A', diag_pivot_thresh=0.0,
                               options=dict(SymmetricMode=True))
            self.kind = 'superlu'

    def solve(self, b):
        return self.F(b) if self.kind == 'cholmod' else self.F.solve(b)

    def op(self):
        return spla.LinearOperator((self.n, self.n), matvec=self.solve, dtype=float)


def lowest_modes(K, M, k, fac):
    v0 = np.ones(K.shape[0])
    lam, vec = spla.eigsh(K, k=k, M=M, sigma=0.0, which='LM', OPinv=fac.op(), v0=v0, tol=1e-12)
    idx = np.argsort(lam)
    lam, vec = lam[idx], vec[:, idx]
    # residual check
    res = [float(np.linalg.norm(K @ vec[:, i] - lam[i] * (M @ vec[:, i])) /
                 np.linalg.norm(K @ vec[:, i])) for i in range(k)]
    return lam, vec, res


def classify(u_full, m, mirror):
    """Label a mode by the M-weighted share of ux/uy/uz and its symmetry about z = 12.5.
    m is the scalar (per-node) consistent mass matrix; M = m (x) I3."""
    n = len(u_full) // 3
    U = u_full.reshape(n, 3)

    def energy(V):
        return float(sum(V[:, c] @ (m @ V[:, c]) for c in range(3)))
    tot = energy(U)
    shares = [float(U[:, c] @ (m @ U[:, c]) / tot) for c in range(3)]
    sym = None
    if mirror is not None:
        Ur = U[mirror].copy()
        Ur[:, 2] *= -1.0
        sym = energy(0.5 * (U + Ur)) / tot
    c = int(np.argmax(shares))
    if c == 1:
        label = ('bending' if sym is not None and sym > 0.5 else 'torsion')
    elif c == 2:
        label = 'in-plane bending' if sym is not None and sym < 0.5 else 'in-plane (z-sym)'
    else:
        label = 'axial'
    return label, shares, sym


def mirror_map(X):
    Xm = X.copy()
    Xm[:, 2] = WIDTH - Xm[:, 2]
    d, idx = cKDTree(X).query(Xm)
    if d.max() > 1e-6:
        return None
    return idx


# ----------------------------------------------------------------------------
# one refinement level
# ----------------------------------------------------------------------------

def contact_statics(Kr, F, T, iface, kappa, q0, nr):
    """Frictionless penalty contact on the interface, per area: p = kappa max(0, -g) at the
    Gauss points of the interface faces (g = u_y(B) - u_y(A), small displacements; the
    consistent surface integral of a node-matching interface), solved by active-set
    iteration (semi-smooth Newton on the piecewise-linear problem) from the contact of the
    solution without it.  Returns the resultant int p dA, the contact area, the peak
    pressure, the largest penetration and the master's displacement."""
    node_a, node_b, N, wJ = iface['node_a'], iface['node_b'], iface['N'], iface['wJ']
    ne, ng = wJ.shape
    nn = N.shape[1]
    rows = np.broadcast_to(np.arange(ne * ng).reshape(ne, ng, 1), (ne, ng, nn)).ravel()
    vals = np.broadcast_to(N[None, :, :], (ne, ng, nn)).ravel()
    cols_b = np.broadcast_to((3 * node_b + 1)[:, None, :], (ne, ng, nn)).ravel()
    cols_a = np.broadcast_to((3 * node_a + 1)[:, None, :], (ne, ng, nn)).ravel()
    G = sp.csr_matrix((np.concatenate([vals, -vals]),
                       (np.concatenate([rows, rows]), np.concatenate([cols_b, cols_a]))),
                      shape=(ne * ng, T.shape[0]))
    GT = (G @ T).tocsr()
    w = kappa * wJ.ravel()
    active = (GT @ q0) < 0
    history = []
    GTt = GT.T.tocsc()
    fac = Factor((Kr + GT.T @ sp.diags(w * active) @ GT).tocsc())
    for it in range(1, 61):
        q = fac.solve(F)
        gap = GT @ q
        new = gap < 0
        history.append(int(new.sum()))
        changed = int((new != active).sum())
        log(f"    contact iteration {it}: {int(new.sum())} of {len(new)} Gauss points closed, "
            f"{changed} changed")
        if changed == 0:
            break
        if fac.kind == 'cholmod' and changed <= 500:
            # rank-k update and downdate of the factor by the points that closed / opened
            # (a refactorization is cheaper for larger changes)
            for sel, sub in ((new & ~active, False), (active & ~new, True)):
                idx = np.flatnonzero(sel)
                if len(idx):
                    fac.F.update_inplace((GTt[:, idx] @ sp.diags(np.sqrt(w[idx]))).tocsc(),
                                         subtract=sub)
        else:
            fac = Factor((Kr + GT.T @ sp.diags(w * new) @ GT).tocsc())
        active = new
    else:
        raise RuntimeError('contact active set did not settle in 60 iterations')
    pen = np.maximum(-gap, 0.0)
    p = kappa * pen
    force = p * wJ.ravel()
    xz = iface['xz'].reshape(-1, 2)
    near_end = (xz[:, 0] < 45.0) | (xz[:, 0] > 120.0)
    d_weld = np.min([np.hypot(xz[:, 0] - wx, xz[:, 1] - WELD_Z) for wx in WELDS_X], axis=0)
    total = float(force.sum())
    return dict(kappa_n_per_mm3=kappa,
                contact_resultant_n=total,
                contact_area_mm2=float(wJ.ravel()[gap < 0].sum()),
                interface_area_mm2=iface['area'],
                peak_pressure_n_per_mm2=float(p.max()),
                max_penetration_mm=float(pen.max()),
                max_penetration_over_thickness=float(pen.max() / T_SHEET),
                share_within_5mm_of_sheet_ends=float(force[near_end].sum() / total),
                share_within_5mm_of_weld_rims=float(force[d_weld < WELD_R + 5.0].sum() / total),
                master_displacement=q[nr:].tolist(),
                gauss_points=int(len(gap)), faces=iface['n_faces'],
                active_set_iterations=len(history), closed_points_history=history)


def run_level(case, refine, nt, nnode, welds, nmodes, grade=1.0, kappa=None):
    nz = 4 * (refine + 1)
    t_start = time.time()
    res = {'refine': refine}
    log(f"level {refine}: nz={nz} nt={nt} hex{nnode} case={case} welds={welds}")
    el, X, conn, esheet, s_n, info, iface = build_3d(case, nz, nt, nnode, welds, grade)
    res['mesh'] = info
    log(f"  mesh: {info['n_elements']} elements, {info['n_nodes']} nodes, {info['n_dof']} dof; "
        f"2-D elements {info['n_2d_elements_by_kind']}")
    if 'bonded_area_mm2' in info:
        log(f"  bonded area {info['bonded_area_mm2']:.6f} mm^2 (exact 2 pi r^2 = "
            f"{info['bonded_area_exact_2_pi_r2']:.6f})")
    t0 = time.time()
    K, m, quality = assemble(el, X, conn)
    res['mesh']['quality'] = quality
    t_asm = time.time() - t0
    log(f"  assembled K (nnz {K.nnz}) and M in {t_asm:.1f} s; quality {quality}")

    # ---------------- sanity checks ----------------
    checks = {}
    Kabs = abs(K).max()
    checks['K_symmetry_rel'] = float(abs(K - K.T).max() / Kabs)
    checks['M_symmetry_rel'] = float(abs(m - m.T).max() / abs(m).max())
    R = rigid_modes(X, center=X.mean(0))
    KR = K @ R
    checks['rigid_body_rel'] = float(np.abs(KR).max() / (Kabs * np.abs(R).max()))
    checks['rigid_body_note'] = 'max|K r| / (max|K| max|r|) over 3 translations + 3 rotations, unconstrained K'
    del KR
    vol = (2 * 125.0 if case == 'friction_bar' else 165.0) * WIDTH * T_SHEET
    M = mass_full(m)
    mass = [float(R[:, c] @ (M @ R[:, c])) for c in range(3)]
    del M, R
    checks['total_mass_t'] = mass
    checks['rho_volume_t'] = RHO * vol
    checks['mass_rel_err'] = float(max(abs(m_ - RHO * vol) for m_ in mass) / (RHO * vol))
    log(f"  checks: {checks}")
    K = (0.5 * (K + K.T)).tocsr()

    mirror = mirror_map(X)
    tol = 1e-6
    ndof = K.shape[0]
    allnodes = np.arange(len(X))
    if case == 'friction_bar':
        clamp_nodes = allnodes[np.abs(X[:, 0]) < tol]
        assert np.all(s_n[clamp_nodes] == 0)
        slave_nodes = allnodes[np.abs(X[:, 0] - 165.0) < tol]
        assert np.all(s_n[slave_nodes] == 1)
    else:
        clamp_nodes = allnodes[(np.abs(X[:, 0]) < tol) | (np.abs(X[:, 0] - 165.0) < tol)]
        slave_nodes = np.zeros(0, dtype=int)
    fixed = np.zeros(ndof, bool)
    slave = np.zeros(ndof, bool)
    for c in range(3):
        fixed[3 * clamp_nodes + c] = True
        slave[3 * slave_nodes + c] = True
    res['n_clamped_nodes'] = int(len(clamp_nodes))
    res['n_tied_nodes'] = int(len(slave_nodes))
    keep = np.flatnonzero(~fixed & ~slave)
    nr = len(keep)
    master_free = case == 'friction_bar' and welds == 'area'

    # Transformation u = T q, q = [retained dofs (not clamped, not tied), master 6 dof].
    # The fixed-interface system (master clamped = tied face clamped) is the leading
    # nr x nr block of the reduced matrices.
    rows, cols, vals = [keep], [np.arange(nr)], [np.ones(nr)]
    nq = nr
    if master_free:
        d = X[slave_nodes] - MASTER
        ones = np.ones(len(slave_nodes))

        def add(comp, mcol, v):
            rows.append(3 * slave_nodes + comp)
            cols.append(np.full(len(slave_nodes), nr + mcol))
            vals.append(v)
        # u_s = u_m + theta x d :  ux = um_x + ry dz - rz dy ; uy = um_y + rz dx - rx dz ;
        #                          uz = um_z + rx dy - ry dx
        add(0, 0, ones); add(0, 4, d[:, 2]); add(0, 5, -d[:, 1])
        add(1, 1, ones); add(1, 5, d[:, 0]); add(1, 3, -d[:, 2])
        add(2, 2, ones); add(2, 3, d[:, 1]); add(2, 4, -d[:, 0])
        nq = nr + 6
    T = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                      shape=(ndof, nq))
    Kr = (T.T @ K @ T).tocsc()
    del K
    M = mass_full(m)
    Mr = (T.T @ M @ T).tocsc()
    del M
    Kr = (0.5 * (Kr + Kr.T)).tocsc()
    Mr = (0.5 * (Mr + Mr.T)).tocsc()
    # ---------------- fixed interface (master clamped) ----------------
    Kf = Kr[:nr, :nr].tocsc()
    Mf = Mr[:nr, :nr].tocsc()
    res['n_dof_fixed_interface'] = int(nr)
    t0 = time.time()
    fac = Factor(Kf)
    t_fac = time.time() - t0
    log(f"  fixed-interface: {nr} dof, factor ({fac.kind}) {t_fac:.1f} s")
    t0 = time.time()
    lam, vec, resid = lowest_modes(Kf, Mf, nmodes, fac)
    t_eig = time.time() - t0
    f_fi = np.sqrt(np.maximum(lam, 0)) / (2 * math.pi)
    labels = []
    for i in range(nmodes):
        u = np.zeros(ndof)
        u[keep] = vec[:, i]
        labels.append(classify(u, m, mirror))
    res['freq_fixed_interface_hz'] = f_fi.tolist()
    res['modes_fixed_interface'] = [dict(label=l_[0], share_xyz=l_[1], zsym_share=l_[2])
                                    for l_ in labels]
    res['eig_residual_max_fixed_interface'] = max(resid)
    log(f"  fixed-interface eigen {t_eig:.1f} s; f = " + ", ".join(f"{f:.3f}" for f in f_fi))
    log("    labels: " + ", ".join(l_[0] for l_ in labels))
    del fac, Kf, Mf, vec
    gc.collect()
    timings = dict(assembly_s=t_asm, factor_fixed_s=t_fac, eig_fixed_s=t_eig)

    if master_free:
        # ---------------- master node free (rigid tie eliminated) ----------------
        res['n_dof_master_free'] = int(nq)
        t0 = time.time()
        fac = Factor(Kr)
        t_fac2 = time.time() - t0
        # statics
        F = np.zeros((nq, 3))
        F[nr + 1, 0] = FY
        F[nr + 3, 1] = MX
        F[nr + 1, 2] = FY
        F[nr + 3, 2] = MX
        Q = np.column_stack([fac.solve(F[:, j]) for j in range(3)])
        st_res = [float(np.linalg.norm(Kr @ Q[:, j] - F[:, j]) / np.linalg.norm(F[:, j]))
                  for j in range(3)]
        um = Q[nr:, :]
        # tie check: tied-face displacement equals the rigid motion of the master
        u_full = T @ Q[:, 0]
        us = u_full.reshape(-1, 3)[slave_nodes]
        dd = X[slave_nodes] - MASTER
        rig = um[:3, 0][None, :] + np.cross(um[3:, 0][None, :], dd)
        checks['tie_rigid_motion_err'] = float(np.abs(us - rig).max() / np.abs(rig).max())
        res['statics_master_displacement'] = {
            'dofs': ['ux', 'uy', 'uz', 'rx', 'ry', 'rz'],
            'Fy=-0.7': um[:, 0].tolist(),
            'Mx=-20': um[:, 1].tolist(),
            'Fy=-0.7 & Mx=-20': um[:, 2].tolist(),
            'flexibility_uy_per_Fy_mm_per_N': float(um[1, 0] / FY),
            'flexibility_rx_per_Mx_rad_per_Nmm': float(um[3, 1] / MX),
            'symmetry_decoupling': 'Fy (z-symmetric) and Mx (z-antisymmetric) are uncoupled; '
                                   'uz, rx, ry under Fy and ux, uy, rz under Mx are round-off',
            'residual_rel': st_res,
        }
        log(f"  statics (factor {t_fac2:.1f} s): Fy -> {np.array2string(um[:, 0], precision=7)}")
        log(f"                          Mx -> {np.array2string(um[:, 1], precision=7)}")
        log(f"                        both -> {np.array2string(um[:, 2], precision=7)}")
        if kappa is not None:
            t0 = time.time()
            cs = contact_statics(Kr, F[:, 2], T, iface, kappa, Q[:, 2], nr)
            cs['cpu_s'] = time.time() - t0
            res['contact_statics'] = cs
            log(f"  contact statics (kappa {kappa} N/mm^3, {cs['cpu_s']:.1f} s): resultant "
                f"{cs['contact_resultant_n']:.4f} N, area {cs['contact_area_mm2']:.2f} mm^2, "
                f"peak {cs['peak_pressure_n_per_mm2']:.4f} N/mm^2, u_y "
                f"{cs['master_displacement'][1]:.6f} mm")
        t0 = time.time()
        lam, vec, resid = lowest_modes(Kr, Mr, nmodes, fac)
        t_eig2 = time.time() - t0
        f_mf = np.sqrt(np.maximum(lam, 0)) / (2 * math.pi)
        labels = [classify(T @ vec[:, i], m, mirror) for i in range(nmodes)]
        res['freq_master_free_hz'] = f_mf.tolist()
        res['modes_master_free'] = [dict(label=l_[0], share_xyz=l_[1], zsym_share=l_[2])
                                    for l_ in labels]
        res['eig_residual_max_master_free'] = max(resid)
        log(f"  master-free eigen {t_eig2:.1f} s; f = " + ", ".join(f"{f:.3f}" for f in f_mf))
        log("    labels: " + ", ".join(l_[0] for l_ in labels))
        timings.update(factor_master_free_s=t_fac2, eig_master_free_s=t_eig2)
        del fac
    del Kr, Mr
    gc.collect()
    res['solver'] = 'cholmod' if _have_cholmod() else 'superlu'
    res['checks'] = checks
    timings['total_s'] = time.time() - t_start
    res['timings'] = timings
    res['peak_rss_gb'] = peak_mem_gb()
    log(f"  level {refine} done in {timings['total_s']:.1f} s, peak RSS {res['peak_rss_gb']:.2f} GB")
    return res


def _have_cholmod():
    try:
        import sksparse.cholmod  # noqa: F401
        return True
    except ImportError:
        return False


def rel_diffs(a, b):
    a, b = np.asarray(a, float), np.asarray(b, float)
    return ((a - b) / np.where(np.abs(b) > 0, np.abs(b), 1.0)).tolist()


def extrapolate(hs, vals):
    """Richardson-type estimate from the last three levels, error ~ C h^p.
    Returns (estimate, p) or (finest, None) when the sequence is not monotone."""
    (h1, h2, h3), (f1, f2, f3) = hs[-3:], vals[-3:]
    d12, d23 = f2 - f1, f3 - f2
    if d12 == 0 or d23 == 0 or np.sign(d12) != np.sign(d23) or abs(d23) >= abs(d12):
        return f3, None
    target = d12 / d23

    def g(p):
        return (h1 ** p - h2 ** p) / (h2 ** p - h3 ** p) - target
    lo, hi = 0.2, 12.0
    if g(lo) * g(hi) > 0:
        return f3, None
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if g(lo) * g(mid) <= 0:
            hi = mid
        else:
            lo = mid
    p = 0.5 * (lo + hi)
    est = f3 + d23 * h3 ** p / (h2 ** p - h3 ** p)
    return float(est), float(p)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('--case', choices=['friction_bar', 'strip'], default='friction_bar')
    ap.add_argument('--refine', default='1', help='level or comma list of levels; nz = 4 (N + 1)')
    ap.add_argument('--welds', choices=['area', 'none'], default='area',
                    help="'none' = sheets not bonded (only the fixed-interface problem is solvable)")
    ap.add_argument('--nt', default='2',
                    help='elements through each sheet thickness; one value or a comma list matching --refine')
    ap.add_argument('--elem', type=int, choices=[20, 27], default=20)
    ap.add_argument('--grade', type=float, default=8.0,
                    help='edge grading: element size at free, clamped and tied edges = '
                         '(25/nz)/grade, growth ratio 1.4 (default 8; 1 = uniform strips and '
                         'full-width weld boxes)')
    ap.add_argument('--modes', type=int, default=None)
    ap.add_argument('--contact-per-area', type=float, default=None, metavar='KAPPA',
                    help='also solve the statics under Fy & Mx with frictionless penalty contact '
                         'on the interface, KAPPA N/mm^3 per area (friction bar only)')
    ap.add_argument('--out', required=True)
    args = ap.parse_args()
    levels = [int(v) for v in str(args.refine).split(',')]
    nts = [int(v) for v in str(args.nt).split(',')]
    if len(nts) == 1:
        nts = nts * len(levels)
    if len(nts) != len(levels):
        ap.error('--nt must be one value or as many values as --refine')
    nmodes = args.modes or (10 if args.case == 'friction_bar' else 6)
    out = dict(case=args.case, welds=args.welds, element=f'hex{args.elem}', grade=args.grade,
               integration='3x3x3 Gauss', mass='consistent',
               material=dict(E=E_MOD, nu=NU, rho=RHO),
               units='mm, N, t, s; frequencies in Hz; rotations in rad',
               command=' '.join(['python3'] + sys.argv), levels=[])
    if args.case == 'friction_bar':
        out['geometry'] = dict(sheet_A=dict(x=[0, 125], z=[0, 25], y=[-0.25, 0.25]),
                               sheet_B=dict(x=[40, 165], z=[0, 25], y=[0.25, 0.75]),
                               welds=[dict(x=x, z=WELD_Z, diameter=2 * WELD_R) for x in WELDS_X],
                               clamp='sheet A face x=0, all translations',
                               tie='sheet B face x=165 rigid to master (165,0.5,12.5), 6 DOF, exact elimination',
                               load=dict(Fy=FY, Mx=MX))
    else:
        out['geometry'] = dict(strip=dict(x=[0, 165], z=[0, 25], y=[-0.25, 0.25]),
                               clamp='faces x=0 and x=165, all translations')
    for N, nt in zip(levels, nts):
        out['levels'].append(run_level(args.case, N, nt, args.elem, args.welds, nmodes, args.grade,
                                       args.contact_per_area))
        with open(args.out, 'w') as fh:
            json.dump(out, fh, indent=1)
    # differences between successive levels and an extrapolated estimate
    L = out['levels']
    keys = ['freq_fixed_interface_hz', 'freq_master_free_hz']
    diffs = []
    for i in range(1, len(L)):
        d = dict(coarse=dict(refine=L[i - 1]['refine'], nt=L[i - 1]['mesh']['nt']),
                 fine=dict(refine=L[i]['refine'], nt=L[i]['mesh']['nt']))
        for k in keys:
            if k in L[i]:
                d[k + '_rel'] = rel_diffs(L[i - 1][k], L[i][k])
        if 'statics_master_displacement' in L[i]:
            a, b = L[i - 1]['statics_master_displacement'], L[i]['statics_master_displacement']
            for lk in ['Fy=-0.7', 'Mx=-20', 'Fy=-0.7 & Mx=-20']:
                d['statics_' + lk + '_rel'] = rel_diffs(a[lk], b[lk])
        diffs.append(d)
    out['differences_successive_levels'] = diffs
    if len(L) >= 3:
        # mesh-size parameter: 1/nz when the in-plane mesh changes, else 1/nt
        if len({L_['mesh']['nz'] for L_ in L[-3:]}) == 3:
            hs = [1.0 / L_['mesh']['nz'] for L_ in L]
        else:
            hs = [1.0 / L_['mesh']['nt'] for L_ in L]
        out['extrapolation_note'] = ('from the last three levels assuming error = C h^p, '
                                     'h = 1/nz (or 1/nt if only nt changes); entries are '
                                     '[estimate, p]; p = null means not monotone -> finest value')
        ext = {}
        for k in keys:
            if k in L[-1]:
                ext[k] = [extrapolate(hs, [L_[k][j] for L_ in L]) for j in range(len(L[-1][k]))]
        if 'statics_master_displacement' in L[-1]:
            for lk in ['Fy=-0.7', 'Mx=-20', 'Fy=-0.7 & Mx=-20']:
                ext['statics_' + lk] = [extrapolate(hs, [L_['statics_master_displacement'][lk][j]
                                                         for L_ in L]) for j in range(6)]
        out['extrapolated_estimate_value_and_order'] = ext
    with open(args.out, 'w') as fh:
        json.dump(out, fh, indent=1)
    log(f"wrote {args.out}")


if __name__ == '__main__':
    main()
