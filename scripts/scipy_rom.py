#!/usr/bin/env python3
"""Integrates a reduced model exported by `jointrom export` with SciPy's `solve_ivp` (BDF capped at
order 2 like jointrom, or LSODA) and an analytic Jacobian, and compares curves, steps and wall time
with jointrom's own run of the same file (jointrom against an established integrator).

    python3 scripts/scipy_rom.py ROM.json [--jointrom target/release/jointrom] [--method BDF|LSODA]
                                 [--end-time T]

The model is the ROM file's (`src/reduction/rom_file.rs`): M q'' + K q = Φ_mᵀ F(t) − (BΦ)ᵀ p(BΦ q, s)
with the viscoplastic Coulomb law of `src/joint/law.rs` (penalty k_n, stick stiffness k_t, μ,
relaxation τ), written here independently with NumPy. State y = [q, v, s / 1e-3 mm]; jointrom's
W and D states are left out (they do not feed back). Tolerances as jointrom's defaults: rtol 1e-8,
atol 1e-6 mm of the physical field (q_j: atol · L / coordinate_size_j, v_j: 1e3 × that, s: 1e-6 · L
in units of 1e-3 mm, L = √((2 field_dofs + 2w + 2) / (2r + 2w + 2)): jointrom's error test of a
reduced model, the full model's on the field — `src/integrate/mechanical.rs`; older files without
`field_dofs`: L = 1). Needs numpy and scipy (pip install scipy)."""
import argparse
import json
import math
import subprocess
import sys
import time

import numpy as np
from scipy.integrate import solve_ivp
import scipy.integrate._ivp.bdf as bdf_module

SLIP_SCALE = 1e-3


class Bdf2(bdf_module.BDF):
    """SciPy's BDF with the order capped at 2 (its arrays are built for order 5, then the step
    logic reads the module's MAX_ORDER, set to 2 once the solver exists)."""

    def __init__(self, *args, **kwargs):
        bdf_module.MAX_ORDER = 5
        super().__init__(*args, **kwargs)
        bdf_module.MAX_ORDER = 2
VELOCITY_SCALE = 1e3


class Rom:
    def __init__(self, doc):
        self.r = doc["dimension"]
        self.w = doc["pairs"]
        self.M = np.array(doc["mass"])
        self.K = np.array(doc["stiffness"])
        self.B = np.array(doc["joint_operator"])
        self.Pm = np.array(doc["master_rows"])
        ml = doc["master_load"]
        self.F = np.array([ml["fx"], ml["fy"], ml["fz"], ml["mx"], ml["my"], ml["mz"]])
        self.ramp = doc["load_ramp"]["duration"]
        c = doc["contact"]
        self.kn, self.mu, self.kt = c["normal_stiffness"], c["friction_coefficient"], c["stick_stiffness"]
        self.tau = doc["friction_relaxation_time"]
        self.size = np.array(doc["coordinate_size"])
        self.field_dofs = doc.get("field_dofs", len(self.size))
        self.end = doc["end_time"]
        self.Minv = np.linalg.inv(self.M)
        self.Bn, self.B1, self.B2 = self.B[0::3], self.B[1::3], self.B[2::3]

    def load(self, t):
        f = 0.0 if t <= 0 else 1.0 if t >= self.ramp else 0.5 * (1 - math.cos(math.pi * t / self.ramp))
        return self.Pm.T @ (self.F * f)

    def law(self, q, s):
        """Per pair: p_n, p_t (w × 2), s' (w × 2), and the branch masks."""
        g = self.Bn @ q
        ut = np.stack([self.B1 @ q, self.B2 @ q], axis=1)
        e = ut - s
        rr = np.hypot(e[:, 0], e[:, 1])
        closed = g < 0
        c = np.where(closed, self.mu * self.kn * (-g) / self.kt, 0.0)
        stick = closed & (rr <= c)
        slip = closed & ~stick
        pn = self.kn * np.minimum(g, 0.0)
        n = e / np.maximum(rr, 1e-300)[:, None]
        pt = np.zeros_like(e)
        pt[stick] = self.kt * e[stick]
        pt[slip] = (self.kt * c[slip])[:, None] * n[slip]
        sd = np.zeros_like(e)
        sd[~closed] = e[~closed] / self.tau
        sd[slip] = ((rr[slip] - c[slip]) / self.tau)[:, None] * n[slip]
        return g, e, rr, c, closed, stick, slip, n, pn, pt, sd

    def rhs(self, t, y):
        r, w = self.r, self.w
        q, v, s = y[:r], y[r:2 * r], y[2 * r:].reshape(w, 2) * SLIP_SCALE
        _, _, _, _, _, _, _, _, pn, pt, sd = self.law(q, s)
        force = self.load(t) - self.K @ q - self.Bn.T @ pn - self.B1.T @ pt[:, 0] - self.B2.T @ pt[:, 1]
        return np.concatenate([v, self.Minv @ force, (sd / SLIP_SCALE).ravel()])

    def jac(self, t, y):
        r, w = self.r, self.w
        q, s = y[:r], y[2 * r:].reshape(w, 2) * SLIP_SCALE
        g, e, rr, c, closed, stick, slip, n, pn, pt, sd = self.law(q, s)
        # Per pair derivatives of p = [p_n, p_t1, p_t2] and s' in (g, u_t) and s.
        dpn_dg = np.where(closed, self.kn, 0.0)
        dpt_du = np.zeros((w, 2, 2))
        dpt_dg = np.zeros((w, 2))
        dsd_du = np.zeros((w, 2, 2))
        dsd_dg = np.zeros((w, 2))
        eye = np.eye(2)
        dpt_du[stick] = self.kt * eye
        dsd_du[~closed] = eye / self.tau
        if slip.any():
            ns = n[slip]
            nn = ns[:, :, None] * ns[:, None, :]
            perp = eye - nn
            alpha = self.kt * c[slip] / rr[slip]
            rho = (rr[slip] - c[slip]) / rr[slip]
            dc_dg = -self.mu * self.kn / self.kt
            dpt_du[slip] = alpha[:, None, None] * perp
            dpt_dg[slip] = self.kt * dc_dg * ns
            dsd_du[slip] = (nn + rho[:, None, None] * perp) / self.tau
            dsd_dg[slip] = -dc_dg * ns / self.tau
        Bt = np.stack([self.B1, self.B2], axis=1)  # w × 2 × r
        # ∂p_t/∂q = dpt_du B_t + dpt_dg B_n ; ∂p_t/∂s = −dpt_du
        dpt_dq = np.einsum("wij,wjr->wir", dpt_du, Bt) + dpt_dg[:, :, None] * self.Bn[:, None, :]
        dforce_dq = -self.K - self.Bn.T @ (dpn_dg[:, None] * self.Bn) - np.einsum("wir,wic->rc", Bt, dpt_dq)
        dforce_ds = np.einsum("wir,wij->rwj", Bt, dpt_du).reshape(r, 2 * w) * SLIP_SCALE
        dsd_dq = np.einsum("wij,wjr->wir", dsd_du, Bt) + dsd_dg[:, :, None] * self.Bn[:, None, :]
        J = np.zeros((2 * r + 2 * w, 2 * r + 2 * w))
        J[:r, r:2 * r] = np.eye(r)
        J[r:2 * r, :r] = self.Minv @ dforce_dq
        J[r:2 * r, 2 * r:] = self.Minv @ dforce_ds
        J[2 * r:, :r] = dsd_dq.reshape(2 * w, r) / SLIP_SCALE
        ds = np.zeros((2 * w, 2 * w))
        for k in range(w):
            ds[2 * k:2 * k + 2, 2 * k:2 * k + 2] = -dsd_du[k]
        J[2 * r:, 2 * r:] = ds
        return J

    def curves(self, q_t, s_t):
        fc, fr, uy = [], [], []
        for q, s in zip(q_t, s_t):
            *_, pn, pt, _ = self.law(q, s.reshape(self.w, 2) * SLIP_SCALE)
            fc.append(float(np.linalg.norm(pn)))
            fr.append(float(np.linalg.norm(pt)))
            uy.append(float(self.Pm[1] @ q))
        return fc, fr, uy


def rel_l2(a, b):
    n = min(len(a), len(b))
    num = sum((a[i] - b[i]) ** 2 for i in range(n))
    den = sum(b[i] ** 2 for i in range(n))
    return math.sqrt(num / den) if den > 0 else float("nan")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("rom")
    ap.add_argument("--jointrom", default="target/release/jointrom")
    ap.add_argument("--method", default="BDF", choices=["BDF", "LSODA"])
    ap.add_argument("--end-time", type=float)
    a = ap.parse_args()
    doc = json.load(open(a.rom))
    rom = Rom(doc)
    end = a.end_time or rom.end
    r, w = rom.r, rom.w
    length = math.sqrt((2 * rom.field_dofs + 2 * w + 2) / (2 * r + 2 * w + 2))
    atol = length * np.concatenate([1e-6 / rom.size, 1e-6 * VELOCITY_SCALE / rom.size, np.full(2 * w, 1e-6)])
    t_eval = np.arange(0, round(end / 1e-4) + 1) * 1e-4
    t_eval[-1] = min(t_eval[-1], end)
    start = time.perf_counter()
    sol = solve_ivp(rom.rhs, (0, end), np.zeros(2 * r + 2 * w), method=Bdf2 if a.method == "BDF" else a.method, jac=rom.jac,
                    rtol=1e-8, atol=atol, t_eval=t_eval)
    wall = time.perf_counter() - start
    if not sol.success:
        sys.exit(f"solve_ivp failed: {sol.message}")
    fc, fr, uy = rom.curves(sol.y[:r].T, sol.y[2 * r:].T)
    out = subprocess.run([a.jointrom, "transient", doc["case"], "--model", f"file:{a.rom}",
                          "--end-time", str(end), "--json"], capture_output=True, text=True)
    if out.returncode != 0:
        sys.exit(f"jointrom failed: {out.stderr}")
    j = json.loads(out.stdout)
    c = j["curves"]
    print(f"{doc['case']} r = {r}, {w} pairs, {end} s, scipy {a.method} (max order 2 for BDF), analytic Jacobian")
    print(f"scipy:    {wall:8.3f} s wall, {sol.nfev} RHS, {sol.njev} Jacobians, {sol.nlu} LU")
    print(f"jointrom: {j['wall_s']:8.3f} s wall, {j['stats']['steps']} steps, {j['stats']['rhs_evals']} RHS "
          f"→ {wall / j['wall_s']:.0f}× faster")
    print(f"curves, jointrom against scipy (relative L2): |f_c| {rel_l2(c['contact_force_norm'], fc):.2e}, "
          f"|f_R| {rel_l2(c['friction_force_norm'], fr):.2e}, u_y {rel_l2(c['master_uy'], uy):.2e}")


if __name__ == "__main__":
    main()
