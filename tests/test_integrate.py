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
