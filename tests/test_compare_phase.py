"""Fig. 8's phase-aligned error (issue 25 item 4): it measures the gaits, not the phase drift.

Two synthetic periodic trajectories with the same step shape but step periods 0.70 and
0.58 s (the paper's ideal and the first contact step): time-aligned they drift apart by up to
the full swing amplitude, phase-aligned they agree to the interpolation error.
"""

import numpy as np

from walkerlab.comparison.errors import aligned_errors, phase_aligned_errors
from walkerlab.io.trajectory import NamedTrajectory


def _gait(period, n_steps=6, amp=0.2, rate=1000.0):
    t = np.arange(0.0, n_steps * period + 1e-12, 1.0 / rate)
    k = np.minimum((t // period).astype(int), n_steps - 1)
    s = t / period - k
    shape = amp * np.sin(2 * np.pi * s)  # each step the same shape in normalised step time
    n = len(t)
    return NamedTrajectory(time=t, legs=["leg1", "leg2"],
                           coordinates={"leg1_angle": shape, "leg2_angle": -shape},
                           units={"leg1_angle": "rad", "leg2_angle": "rad"},
                           stance_leg=k % 2, step_index=k, kinetic=np.zeros(n),
                           potential=np.zeros(n))


def test_phase_aligned_error_removes_the_phase_drift():
    ideal, contact = _gait(0.70), _gait(0.58)
    _, err_t = aligned_errors(ideal, contact)
    phase, err_p = phase_aligned_errors(ideal, contact, n_per_step=50)
    assert np.max(np.abs(err_t["leg1_angle"])) > 0.3  # time-aligned: a phase error
    # same shape at the same step fraction: only the linear interpolation error between
    # 1 kHz samples (h^2/8 max|shape''| = 2e-6 rad): < 1e-3 rad
    assert np.max(np.abs(err_p["leg1_angle"])) < 1e-3
    assert phase[0] == 0.0 and np.all(np.diff(phase) > 0)
    assert int(phase[-1]) == 4  # steps 0..4 completed by both (step 5 has no end sample)


def test_phase_aligned_error_sees_a_different_shape():
    ideal, contact = _gait(0.70), _gait(0.70, amp=0.25)
    _, err_p = phase_aligned_errors(ideal, contact, n_per_step=50)
    assert np.max(np.abs(err_p["leg1_angle"])) > 0.049
