"""Integrator behaviour: dense output, fixed step, guards that raise instead of hanging."""
import numpy as np
import pytest

from physics import IntegrationError, load_scene, simulate


def test_dense_output_matches_stepping_to_the_sample_time():
    a = simulate(load_scene("paper", {"solver.rtol": 1e-9}), t_end=0.12)
    b = simulate(load_scene("paper", {"solver.rtol": 1e-9, "solver.output_rate": 1000.0}), t_end=0.12)
    idx = np.rint(b.t * a.model.scene.solver.output_rate).astype(int)
    np.testing.assert_allclose(a.orbit("RB1")[idx], b.orbit("RB1"), atol=1e-8)


def test_tolerance_controls_the_error():
    ref = simulate(load_scene("paper", {"solver.rtol": 1e-10}), t_end=0.12)
    errs = []
    for rtol in (1e-4, 1e-6, 1e-8):
        r = simulate(load_scene("paper", {"solver.rtol": rtol}), t_end=0.12)
        errs.append(np.abs(r.orbit("RB1") - ref.orbit("RB1")).max())
    assert errs[0] > errs[1] > errs[2]
    assert errs[2] < 1e-8


def test_fixed_step_agrees_with_adaptive_and_blows_up_clearly_when_too_large():
    ref = simulate(load_scene("paper", {"solver.rtol": 1e-9}), t_end=0.12)
    fx = simulate(load_scene("paper", {"solver.method": "fixed", "solver.dt": 5e-6}), t_end=0.12)
    assert np.abs(fx.orbit("RB1") - ref.orbit("RB1")).max() < 1e-7
    with pytest.raises(IntegrationError, match="solver.dt"):
        simulate(load_scene("paper", {"solver.method": "fixed", "solver.dt": 1e-3}), t_end=0.2)


def test_step_collapse_and_step_budget_raise_clear_errors():
    with pytest.raises(IntegrationError, match="min_step"):
        simulate(load_scene("paper", {"solver.min_step": 1e-6, "solver.rtol": 1e-10}), t_end=0.15)
    with pytest.raises(IntegrationError, match="max_steps"):
        simulate(load_scene("paper", {"solver.max_steps": 1000}), t_end=0.5)


@pytest.mark.parametrize("overrides", [
    {"contact.friction": 0.5},                                          # impacts, then whirl
    {"effects.sleeve_inertia": False, "effects.thermal": True},         # rolling sleeve, mu(theta)
    {"effects.stator_contact": True, "effects.amb": "actuator", "contact.friction": 0.5},
    {"effects.retainer_bearing": "linear", "effects.friction": "kinematic",
     "contact.law": "hertz_line"},
    {"positions.rb2": 0.3, "contact.friction": 0.5},                  # asymmetric: no twin planes
])
def test_output_sample_diagnostics_equal_the_full_right_hand_sides_bit_for_bit(overrides):
    """The output samples' diagnostics come from the right-hand side without its derivative
    assembly (``dy = None``): every column equals what the full right-hand side (the one the
    integrator calls) fills in at the same state, time and controls, bit for bit, also where the
    second retainer plane copies the first one's (a symmetric drop, ``twin_planes``)."""
    from physics.model import N_AUX, diagnostics, rhs, twin_planes
    from physics.simulate import segments
    r = simulate(load_scene("paper", overrides), t_end=0.13)
    m = r.model
    Y = np.ascontiguousarray(r.Y)
    full = np.empty((len(r.t), N_AUX))
    dy = np.empty(m.n_state)
    for a, b, powered in segments(m, r.t[-1]):
        U = m.controls(powered)
        sel = np.flatnonzero((r.t >= a) & ((r.t <= b) if powered else (r.t >= a)))[::7]
        for k in sel:
            rhs(r.t[k], Y[k], m.P, m.I, U, dy, full[k])
        pruned = np.empty((len(sel), N_AUX))
        diagnostics(r.t[sel], Y[sel], m.P, m.I, U, pruned)
        assert np.array_equal(full[sel], pruned)
        if not powered:      # the samples the metrics read after the fault (sample_diagnostics)
            assert np.array_equal(full[sel], r.aux[sel])
    assert (r.aux[:, 0] > 0.0).any()            # the samples include contact
    twins = [twin_planes(y, m.P, m.I) for y in Y[r.t > 0.11]]
    assert all(twins) != ("positions.rb2" in overrides)        # a symmetric drop stays symmetric
