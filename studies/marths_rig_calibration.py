"""Calibrates the two-actuator rig on the maRTHS coupler and frame to the benchmark's identified plant.

The later study runs the same compensator (RoDeAC) on the benchmark's identified linear plant and on
our nonlinear two-actuator rig; to compare like with like, each actuator's parameters are chosen so
that the linearised coupled rig's 2 x 2 command -> stroke frequency response is close to the
identified plant's (``ID_Control_plant_100Hz_plantFRAME_SS.json``, BENCHMARK.md section 4) over 0-50 Hz.

Fixed: the benchmark's coupler (section 6) and physical frame condensed to (x, theta) (``marths_frame()``,
Guyan), the paper's actuator (A = 82.1 cm^2, p_s = 17 MPa, K_v, K_s, C_F, the flow curve, m_p = 54 kg,
Coulomb friction F_c = 31.6 N, no fixture mass).  Fitted per actuator (log coordinates, SciPy
least_squares): the proportional gain G_p (the loop's bandwidth), the leakage C_l (with the frame's
stiffness, the DC gain and the coupling), the servovalve's f_v and zeta_v, and the compressibility K_a.
Residual: (H_rig - H_id) / max(|H_id|, 0.02), real and imaginary parts, 0 Hz and 80 log-spaced
frequencies from 0.1 to 50 Hz.  The linearisation is about rest with the friction off (the regularised
friction's slope at v = 0 is not the friction a moving piston feels).

Check with the nonlinear rig: orthogonal multisines (command 1 on the bins 4k+1, command 2 on 4k+3 of
0.125 Hz, 0.125-50 Hz, 1.5 mm RMS each: the benchmark's strokes are a few mm) through the full model
(friction, load pressure, flow curve, saturations) at 1024 Hz, dopri5; the FRF from the last two of three
8 s periods.

Writes the rig files (python/servohydraulics/rig_files/marths_2act*.toml), the figure
(docs/figures/marths_rig_frf.png) and the table in docs/multi-actuator.md (between
``<!-- marths_rig_calibration -->`` and ``<!-- /marths_rig_calibration -->``)::

    python studies/marths_rig_calibration.py [--data ../shared/marths-data] [--starts 8] [--write]

(without --write it prints the table and writes nothing).
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
from scipy.optimize import least_squares

import servohydraulics as sh
from servohydraulics.atomic import replace_marked, write_with
from servohydraulics.multi_rig import MARTHS_ANGLES, MARTHS_ARM, RIG_FILES, MultiActuatorRig

ROOT = Path(__file__).resolve().parents[1]
KEYS = ("G_p", "C_l", "f_v", "zeta_v", "K_a")
BOUNDS = {"G_p": (0.05, 50.0), "C_l": (1e-14, 1e-9), "f_v": (20.0, 300.0), "zeta_v": (0.3, 2.0), "K_a": (1e-13, 1e-10)}
FREQS = np.r_[0.0, np.logspace(-1, np.log10(50.0), 80)]
TABLE_FREQS = (0.0, 1.0, 2.0, 5.0, 10.0, 20.0, 50.0)
ENTRIES = ((0, 0), (0, 1), (1, 0), (1, 1))
FS = 1024.0


def identified_frf(data: Path, f: np.ndarray) -> np.ndarray:
    """The identified plant's FRF (n_f, 2, 2), mm/mm = m/m."""
    ss = json.loads((data / "ID_Control_plant_100Hz_plantFRAME_SS.json").read_text())
    A, B, C, D = (np.asarray(ss[k], dtype=float) for k in "ABCD")
    eye = np.eye(A.shape[0])
    return np.stack([C @ np.linalg.solve(2j * np.pi * fk * eye - A, B) + D for fk in f])


def base_rig() -> sh.Rig:
    return sh.zhao2003()


def rigs_from(p: np.ndarray) -> list[sh.Rig]:
    out = []
    for i in range(2):
        r = base_rig()
        for k, v in zip(KEYS, np.exp(p[len(KEYS) * i:len(KEYS) * (i + 1)])):
            setattr(r, k, float(v))
        out.append(r)
    return out


def make_rig(p: np.ndarray) -> MultiActuatorRig:
    return MultiActuatorRig(rigs_from(p), [MARTHS_ARM] * 2, MARTHS_ANGLES, "marths")


def initial_guess() -> np.ndarray:
    """From the identified plant's first poles (2.65 and ~18 Hz) and DC gains: each loop's bandwidth
    G/A (G = K_v K_s C_F G_p) and a servo stiffness A G / C_l of ~1e8 N/m (the frame's stroke stiffness
    is ~2e7 N/m: DC gains of ~0.85)."""
    r = base_rig()
    p = []
    for w in (17.0, 110.0):  # [rad/s]
        gp = w * r.A / (r.K_v * r.K_s * r.C_F_disp)
        cl = r.A * (r.K_v * r.K_s * r.C_F_disp * gp) / 1e8
        p += [np.log(gp), np.log(cl), np.log(80.0), np.log(0.62), np.log(r.K_a)]
    return np.array(p)


def fit(H_id: np.ndarray, starts: int = 0, seed: int = 1) -> tuple[np.ndarray, object, list[float]]:
    """The fit from the physical initial guess, and from ``starts`` random starts about it (log-normal,
    sigma 0.5): returns the best parameters, its solution and the spread of the starts' results (the
    largest relative parameter difference to the first)."""
    W = np.maximum(np.abs(H_id), 0.02)

    def residual(p):
        r = ((make_rig(p).frequency_response(FREQS) - H_id) / W).ravel()
        return np.r_[r.real, r.imag]

    lo = np.log([BOUNDS[k][0] for k in KEYS] * 2)
    hi = np.log([BOUNDS[k][1] for k in KEYS] * 2)
    rng = np.random.default_rng(seed)
    p0 = initial_guess()
    sols, spread = [], []
    for k in range(starts + 1):
        start = p0 if k == 0 else np.clip(p0 + rng.normal(0.0, 0.5, p0.size), lo + 1e-9, hi - 1e-9)
        sols.append(least_squares(residual, start, bounds=(lo, hi), xtol=1e-12, ftol=1e-12, gtol=1e-12,
                                  max_nfev=2000))
        spread.append(float(np.max(np.abs(np.exp(sols[-1].x - sols[0].x) - 1.0))))
    best = min(sols, key=lambda s: s.cost)
    return best.x, best, spread


def nonlinear_frf(rig: MultiActuatorRig, rms: float = 1.5e-3, period: float = 8.0, periods: int = 3,
                  seed: int = 23) -> tuple[np.ndarray, np.ndarray, object]:
    """The full nonlinear rig's FRF from orthogonal multisines: (frequencies, H (n_f, 2, 2), response)."""
    n = int(period * FS)
    df = 1.0 / period
    kmax = int(50.0 / df)
    rng = np.random.default_rng(seed)
    bins = [np.arange(1, kmax + 1, 4), np.arange(3, kmax + 1, 4)]
    t = np.arange(n) / FS
    u = np.zeros((n, 2))
    for j in range(2):
        phases = rng.uniform(0, 2 * np.pi, bins[j].size)
        x = np.sum(np.cos(2 * np.pi * np.outer(t, bins[j] * df) + phases), axis=1)
        u[:, j] = x * rms / np.std(x)
    U = np.tile(u, (periods, 1))
    res = sh.simulate_multi(rig, np.vstack([U, U[:1]]), 1.0 / FS)
    y = np.c_[res["actuator1.stroke"], res["actuator2.stroke"]][1:]  # row k+1: after command row k
    Uf = np.fft.rfft(U[n:].reshape(periods - 1, n, 2), axis=1).mean(axis=0)
    Yf = np.fft.rfft(y[n:].reshape(periods - 1, n, 2), axis=1).mean(axis=0)
    freqs, H = [], []
    for j in range(2):
        for k in bins[j]:
            # y is the stroke at t_(k+1) after command k (a one-sample advance, e^(jwT)); the held command
            # delays by half a sample (e^(-jwT/2) sinc): undo both to compare with the continuous FRFs.
            w_t = 2 * np.pi * k * df / FS
            col = Yf[k] / Uf[k, j] * np.exp(-0.5j * w_t) / np.sinc(k * df / FS)
            freqs.append((k * df, j, col))
    freqs.sort(key=lambda e: e[0])
    f = np.array([e[0] for e in freqs])
    H = np.full((f.size, 2, 2), np.nan + 0j)
    for m, (_, j, col) in enumerate(freqs):
        H[m, :, j] = col
    return f, H, res


def _at(f: np.ndarray, H: np.ndarray, fk: float, j: int) -> complex:
    """H[:, i, j] at the excited bin nearest fk (the multisine excites command j on its own bins)."""
    ok = ~np.isnan(H[:, 0, j])
    m = np.flatnonzero(ok)[np.argmin(np.abs(f[ok] - fk))]
    return f[m], H[m, :, j]


def table(H_id, H_lin, f_nl, H_nl) -> str:
    lines = ["| f [Hz] | entry | identified gain | rig gain (linear) | rig gain (nonlinear) | identified phase [deg] "
             "| rig phase (linear) [deg] | rig phase (nonlinear) [deg] |",
             "|---|---|---|---|---|---|---|---|"]
    for fk in TABLE_FREQS:
        k = int(np.argmin(np.abs(FREQS - fk)))
        for i, j in ENTRIES:
            if fk == 0.0:
                nl_g, nl_p = "-", "-"
            else:
                fb, col = _at(f_nl, H_nl, fk, j)
                nl_g, nl_p = f"{abs(col[i]):.3f} ({fb:.3g} Hz)", f"{np.degrees(np.angle(col[i])):.1f}"
            lines.append(f"| {FREQS[k]:.3g} | H{i + 1}{j + 1} | {abs(H_id[k, i, j]):.3f} | {abs(H_lin[k, i, j]):.3f} "
                         f"| {nl_g} | {np.degrees(np.angle(H_id[k, i, j])):.1f} "
                         f"| {np.degrees(np.angle(H_lin[k, i, j])):.1f} | {nl_p} |")
    return "\n".join(lines)


def errors(H_id, H_lin) -> str:
    band = FREQS > 0
    rows = ["| entry | rms of abs(H_rig - H_id) / abs(H_id), 0.1-50 Hz | largest, at |", "|---|---|---|"]
    for i, j in ENTRIES:
        e = np.abs(H_lin[band, i, j] - H_id[band, i, j]) / np.abs(H_id[band, i, j])
        m = int(np.argmax(e))
        rows.append(f"| H{i + 1}{j + 1} | {np.sqrt(np.mean(e**2)):.3f} | {e[m]:.3f} at {FREQS[band][m]:.3g} Hz |")
    return "\n".join(rows)


def dc_analysis(H_id: np.ndarray, rig: MultiActuatorRig) -> str:
    """Why the DC gains cannot all match: with leaky servo loops on a passive specimen, D^-1 - I =
    Ka^-1 Ks (Ka the servo stiffnesses A K_v K_s C_F G_p / C_l, Ks the frame's stiffness in strokes),
    whose determinant is det(Ks) / (ka1 ka2) > 0; the identified plant's is negative."""
    D_id, D_rig = H_id[0].real, rig.frequency_response([0.0])[0].real
    X_id, X_rig = np.linalg.inv(D_id) - np.eye(2), np.linalg.inv(D_rig) - np.eye(2)
    J = np.array([[1.0, -d * np.sin(a)] for d, a in zip(rig.arms, rig.angles)])
    Ks = np.linalg.inv(J).T @ rig.specimen_matrix("K") @ np.linalg.inv(J)
    ka = [r.A * r.K_v * r.K_s * r.C_F_disp * r.G_p / r.C_l for r in rig.rigs]

    def fmt(m):
        return "[[" + "], [".join(", ".join(f"{v:.4g}" for v in row) for row in m) + "]]"

    return (f"DC: identified D^-1 - I = {fmt(X_id)} (det {np.linalg.det(X_id):.4g}); rig D^-1 - I = {fmt(X_rig)} "
            f"(det {np.linalg.det(X_rig):.4g}); the frame's stiffness in strokes Ks = {fmt(Ks / 1e6)} MN/m; the "
            f"servo stiffnesses A K_v K_s C_F G_p / C_l = {ka[0] / 1e6:.1f} and {ka[1] / 1e6:.1f} MN/m; the identified "
            f"row sums {D_id.sum(axis=1)[0]:.4f}, {D_id.sum(axis=1)[1]:.4f} (rig: {D_rig.sum(axis=1)[0]:.4f}, "
            f"{D_rig.sum(axis=1)[1]:.4f}).")


def figure(H_id, H_lin, f_nl, H_nl):
    from matplotlib.figure import Figure

    fig = Figure(figsize=(12, 5.5), constrained_layout=True)
    axes = fig.subplots(2, 4, sharex=True)
    band = FREQS > 0
    for c, (i, j) in enumerate(ENTRIES):
        ok = ~np.isnan(H_nl[:, i, j])
        for row, fn in ((0, np.abs), (1, lambda h: np.degrees(np.unwrap(np.angle(h))))):
            ax = axes[row, c]
            ax.plot(FREQS[band], fn(H_id[band, i, j]), "k-", lw=2, label="identified plant")
            ax.plot(FREQS[band], fn(H_lin[band, i, j]), "C0--", label="rig, linearised")
            ax.plot(f_nl[ok], fn(H_nl[ok, i, j]), "C1.", ms=3, label="rig, nonlinear (1.5 mm multisine)")
            ax.set_xscale("log")
            ax.grid(True, which="both", alpha=0.3)
        axes[0, c].set_yscale("log")
        axes[0, c].set_title(f"H{i + 1}{j + 1}: command {j + 1} -> stroke {i + 1}")
        axes[1, c].set_xlabel("frequency [Hz]")
    axes[0, 0].set_ylabel("gain [m/m]")
    axes[1, 0].set_ylabel("phase [deg]")
    axes[0, 0].legend(fontsize=7)
    return fig


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--data", type=Path, default=ROOT.parent / "shared" / "marths-data")
    ap.add_argument("--write", action="store_true", help="write the rig files, the figure and the docs table")
    ap.add_argument("--starts", type=int, default=8, help="random starts besides the physical guess")
    args = ap.parse_args()
    H_id = identified_frf(args.data, FREQS)
    p, sol, spread = fit(H_id, args.starts)
    rig = make_rig(p)
    H_lin = rig.frequency_response(FREQS)  # friction left out of the linearisation
    f_nl, H_nl, res = nonlinear_frf(rig)
    params = "\n".join(f"| {k} | " + " | ".join(f"{getattr(r, k):.4g}" for r in rig.rigs) + " |" for k in KEYS)
    text = (f"Fitted parameters (cost {sol.cost:.4g}; {len(spread) - 1} random starts end within "
            f"{max(spread):.1e} of these):\n\n| parameter | actuator 1 | "
            f"actuator 2 |\n|---|---|---|\n{params}\n\n{errors(H_id, H_lin)}\n\n{table(H_id, H_lin, f_nl, H_nl)}\n\n"
            f"Nonlinear check: peak strokes {np.max(np.abs(res['actuator1.stroke'])) * 1e3:.2f} / "
            f"{np.max(np.abs(res['actuator2.stroke'])) * 1e3:.2f} mm, peak forces "
            f"{np.max(np.abs(res['actuator1.force'])) / 1e3:.1f} / {np.max(np.abs(res['actuator2.force'])) / 1e3:.1f} "
            f"kN, peak opposing force {np.max(res['node.opposing_force']) / 1e3:.1f} kN, warnings: "
            f"{res.warnings() or 'none'}.\n\n{dc_analysis(H_id, rig)}")
    print(text)
    if not args.write:
        return
    header = ("# Calibrated to the maRTHS identified plant by studies/marths_rig_calibration.py\n"
              "# (docs/multi-actuator.md); the actuators' structure keys (m, c, k, ...) are not used here.\n")
    sh.save_multi_rig(rig, RIG_FILES / "marths_2act.toml", header=header)
    write_with(ROOT / "docs" / "figures" / "marths_rig_frf.png",
               lambda path: figure(H_id, H_lin, f_nl, H_nl).savefig(path, dpi=110, format="png"))
    replace_marked(ROOT / "docs" / "multi-actuator.md", "marths_rig_calibration", text)


if __name__ == "__main__":
    main()
