"""Linear analysis of the rig, after Zhao et al. (2003).

* :mod:`.closed_form`: Eqs (2), (8)-(14), loop gains, moving mass (the one home of each closed form);
* :mod:`.linear`: linearisation of the C++ model into ``control.StateSpace``, compensator blocks;
* :mod:`.stability`: characteristic polynomial, Routh bound on the P-gain (Fig 6b), root loci;
* :mod:`.design`: compensator design (Fig 6a, delay compensation), delays and modes of LTI loops;
* :mod:`.rpsd`: the linear RPsD loop of Figs 7-10.

LTI objects are python-control ``StateSpace``/``TransferFunction``; SI units
throughout (frequencies in rad/s unless a name ends in ``_hz``).  Importing this
package imports python-control; ``import servohydraulics`` does not.
"""

from .closed_form import (
    G_fu,
    G_fu_compensated,
    G_xu,
    damping_ratio,
    equivalent_viscous_damping,
    loop_gain_displacement,
    loop_gain_force,
    moving_mass,
    natural_frequency,
    omega_cEFT,
    omega_cRPD,
    omega_oil_column,
    servovalve,
    velocity_feedback_gain,
)
from .design import (
    acceptable_band,
    amplitude_compensation_T,
    delay_compensation_T,
    dominant_modes,
    equivalent_delay,
    group_delay,
    structural_mode,
)
from .linear import (
    ALPHA,
    FRICTION_TREATMENTS,
    OUTPUT_UNITS,
    OUTPUTS,
    STATE_UNITS,
    STATES,
    Compensation,
    linear_analysis_rig,
    linearize,
    phase_lead,
    zoh_delay,
)
from .rpsd import RESTORING_FORCES, fig10_variants, rpsd_loop
from .stability import (
    characteristic_polynomial,
    displacement_open_loop,
    max_p_gain,
    max_p_gain_curve,
    rig_with_mass,
    root_locus_gains,
    routh_array,
    routh_stable,
)

__all__ = [
    "ALPHA",
    "Compensation",
    "FRICTION_TREATMENTS",
    "G_fu",
    "G_fu_compensated",
    "G_xu",
    "OUTPUTS",
    "OUTPUT_UNITS",
    "RESTORING_FORCES",
    "STATES",
    "STATE_UNITS",
    "acceptable_band",
    "amplitude_compensation_T",
    "characteristic_polynomial",
    "damping_ratio",
    "delay_compensation_T",
    "displacement_open_loop",
    "dominant_modes",
    "equivalent_delay",
    "equivalent_viscous_damping",
    "fig10_variants",
    "group_delay",
    "linear_analysis_rig",
    "linearize",
    "loop_gain_displacement",
    "loop_gain_force",
    "max_p_gain",
    "max_p_gain_curve",
    "moving_mass",
    "natural_frequency",
    "omega_cEFT",
    "omega_cRPD",
    "omega_oil_column",
    "phase_lead",
    "rig_with_mass",
    "root_locus_gains",
    "routh_array",
    "routh_stable",
    "rpsd_loop",
    "servovalve",
    "structural_mode",
    "velocity_feedback_gain",
    "zoh_delay",
]
