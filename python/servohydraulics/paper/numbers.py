"""The numbers of docs/methods.md (the same runs as tests/python/test_methods.py), from the
experiments: ``python -m servohydraulics.paper.numbers``.  About 30 s on one core."""

from __future__ import annotations

import numpy as np

from ..rig import zhao2003
from . import experiments as xp

#: EFT runs: label -> (linear model?, amplitude [N], run_eft keywords)
EFT = {"fig3a linear model, none": (True, 2.3e3, {"compensation": "none"}),
       "fig3b linear model, linear": (True, 2.3e3, {}),
       "full model 2.3 kN, linear": (False, 2.3e3, {}),
       "full model 2.3 kN, nonlinear": (False, 2.3e3, {"compensation": "nonlinear"}),
       "fig4b full model 8.9 kN, linear": (False, 8.9e3, {}),
       "fig4c full model 8.9 kN, nonlinear": (False, 8.9e3, {"compensation": "nonlinear"}),
       "linear model, lead 0 (under)": (True, 2.3e3, {"lead_T": 0.0}),
       "linear model, lead 5.28 ms (+ZOH)": (True, 2.3e3, {"lead_T": 5.28e-3}),
       "linear model, lead 12 ms (over)": (True, 2.3e3, {"lead_T": 12e-3}),
       "linear model, lead 40 ms (over)": (True, 2.3e3, {"lead_T": 40e-3})}

#: RPsD free vibrations from 1.6 cm (full model): label -> run_rpsd keywords
RPSD = {"(a) calculated displacement, T_ld 0": {"restoring_force": "calculated_displacement"},
        "(b) T_ld 0": {"delay_T": 0.0}, "(b) T_ld 6 ms": {"delay_T": 6e-3},
        "(b) T_ld 11.2 ms": {"delay_T": 11.2e-3}, "(b) T_ld 16 ms": {"delay_T": 16e-3},
        "(b) T_ld 20 ms": {"delay_T": 20e-3},
        "(c) measured force, 100 % mass": {"restoring_force": "measured_force"},
        "(b) 2 % mass": {"physical_mass_fraction": 0.02},
        "(c) measured force, 2 % mass": {"restoring_force": "measured_force", "physical_mass_fraction": 0.02},
        "(d) pA minus (m + m_p) a + c v": {"restoring_force": "measured_force_corrected",
                                           "force_measurement": "actuator_pressure"},
        "(d) pA minus m a + c v (piston ignored)": {"restoring_force": "measured_force_corrected",
                                                    "force_measurement": "actuator_pressure",
                                                    "subtract_mass": 7084.0}}

RELEASE = xp.Release(free=4.0, fit=4.0)


def _eft_text(s: xp.EftSweep) -> str:
    f, H, res = s.frequency, s.ratio, s.result
    return (f"|F/P| min {H.min():.3f} at {f[np.argmin(H)]:.2f} Hz, max {H.max():.3f} at {f[np.argmax(H)]:.2f} Hz, "
            f"max |spool| {np.max(np.abs(res.spool)):.3f}, max |x| {np.max(np.abs(res.displacement)) * 1e3:.1f} mm")


def _fv_text(r: xp.RpsdRelease) -> str:
    return f"f_d {r.fit.frequency:.4f} Hz, zeta {r.fit.damping_ratio * 100:+.2f} %"


def paper_numbers(sweep_duration: float = 20.0) -> dict:
    """Label -> the numbers of one run, in words."""
    full = zhao2003()
    lin, flowlin = xp.linear_effects(full), xp.with_effects(full, flow_nonlinearity=False)
    out = {f"EFT {label}": _eft_text(xp.eft_sweep(lin if linear else full, amp, sweep_duration, **kw))
           for label, (linear, amp, kw) in EFT.items()}
    out.update({f"RPsD free vibration {label}": _fv_text(xp.rpsd_release(full, RELEASE, **kw))
                for label, kw in RPSD.items()})
    for T in (6e-3, 11.2e-3, 16e-3):
        out[f"RPsD free vibration (b) T_ld {T * 1e3:g} ms, flow nonlinearity off"] = _fv_text(
            xp.rpsd_release(flowlin, RELEASE, delay_T=T))
    tr = xp.tracking_sweep(full, sweep_duration)
    if tr.first_limit_time is not None:
        out["1.27 cm sweep first supply/capacity flag"] = (f"t = {tr.first_limit_time:.2f} s, "
                                                           f"f = {tr.first_limit_frequency:.2f} Hz")
    out["1.27 cm sweep warnings"] = "; ".join(tr.result.warnings())
    return out


if __name__ == "__main__":
    for k, v in paper_numbers().items():
        print(f"{k}: {v}")
