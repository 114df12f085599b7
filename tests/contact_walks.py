"""A scene's compliant-contact walk against its rigid walk, read independently of the
capability table's comparison (:func:`walkerlab.api.capabilities._contact_against_rigid`),
for the slow tests that walk a 3D walker in contact."""

from __future__ import annotations

import h5py
import numpy as np

from walkerlab.api.capabilities import _contact_against_rigid
from walkerlab.stages import pipeline


def contact_period_against_rigid(scene, runs) -> float:
    """Run ``contact-sim``, ``fixedpoint`` and ``simulate`` of ``scene`` into ``runs``;
    assert the contact walk made >= 10 heel strikes and that the table's comparison line
    states the period computed here; return the mean step period of the last four steps
    both walks made, relative to the rigid walk's same steps (contact / rigid - 1)."""
    cs = pipeline.run("contact-sim", scene, runs).path
    fp = pipeline.run("fixedpoint", scene, runs).path
    sim = pipeline.run("simulate", scene, runs).path
    with h5py.File(cs) as f, h5py.File(sim) as s:
        assert int(f["summary/heel_strikes"][()]) >= 10
        h = np.asarray(f["events/heel_strike_times"][:], float)
        hr = np.asarray(s["steps/t_end"][:], float)
    k = min(h.size, hr.size)
    period = (h[k - 1] - h[k - 5]) / (hr[k - 1] - hr[k - 5]) - 1.0
    _value, line = _contact_against_rigid(cs, fp, sim)
    assert f"period {100 * period:+.2f} %" in line
    return period
