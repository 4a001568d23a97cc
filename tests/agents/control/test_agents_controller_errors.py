"""Controller mistakes are errors that name the controller, never silent changes or tracebacks:
unknown channels, values outside [-1, 1] (unit mistakes), wrong shapes, exceptions in user code,
and per-episode state that leaks from one episode into the next."""
import numpy as np
import pytest

from agents.control.controllers import BASELINES, Controller, Passive, check_controller, make_controller
from agents.control.plant import ControllerError, Plant, make_env
from agents.benchmarking.rollout import check_actor, run_episodes

SHORT = dict(episode_time=0.03, terminate_on_failure=False)
CONTINUOUS = dict(command="continuous", **SHORT)


@pytest.fixture(scope="module")
def damping():
    env = make_env("RotorDrop-Damping-v1", **SHORT)
    obs, _ = env.reset(seed=0)
    yield Plant.from_env(env), obs
    env.close()


def returning(value, needs=("damping",)):
    """A controller class whose commands are ``value(n)``."""
    class User(Controller):
        name = "user"

        def commands(self, obs):
            return value(len(obs))
    User.needs = needs
    return User


def act(cls, plant, obs, n=1):
    return make_controller(cls, plant).predict(np.stack([obs] * n))[0]


def error(cls, plant, obs, n=1) -> str:
    with pytest.raises(ControllerError) as info:
        act(cls, plant, obs, n)
    return str(info.value)


def test_a_misspelled_channel_is_named_with_the_controller_and_the_plants_channels(damping):
    plant, obs = damping
    msg = error(returning(lambda n: {"dampnig": np.ones((n, 2))}), plant, obs)
    assert "'dampnig'" in msg and "controller 'user' (User)" in msg
    assert "did you mean 'damping'" in msg and "RotorDrop-Damping-v1 has the channels damping" in msg


def test_a_channel_the_environment_lacks_is_an_error():
    env = make_env("RotorDrop-Relevitate-v1", **CONTINUOUS)
    plant, (obs, _) = Plant.from_env(env), env.reset(seed=0)
    msg = error(returning(lambda n: {"currents": np.zeros((n, 4)), "damping": np.ones((n, 2))},
                          needs=("currents",)), plant, obs)
    assert "'damping' is not an action" in msg and "has the channels currents" in msg
    env.close()


@pytest.mark.parametrize("value,shown", [(5000.0, "5000"), (-1.5, "-1.5"), (np.nan, "nan")])
def test_values_outside_the_normalised_range_are_errors_not_clipped(damping, value, shown):
    """Returning N s/m instead of the normalised command was clipped to C_max silently."""
    plant, obs = damping
    msg = error(returning(lambda n: {"damping": np.full((n, 2), value)}), plant, obs)
    assert f"channel 'damping' value {shown} is outside the allowed range [-1, 1]" in msg
    assert "controller 'user'" in msg and "not N s/m" in msg


def test_round_off_beyond_one_is_accepted_and_clipped(damping):
    plant, obs = damping
    a = act(returning(lambda n: {"damping": np.full((n, 2), 1.0 + 1e-7)}), plant, obs)
    assert np.array_equal(a, np.ones((1, 2), dtype=np.float32))


def test_currents_in_amperes_are_named_as_such():
    env = make_env("RotorDrop-Relevitate-v1", **CONTINUOUS)
    plant, (obs, _) = Plant.from_env(env), env.reset(seed=0)
    msg = error(returning(lambda n: {"currents": np.full((n, 4), 2.5)}, needs=("currents",)),
                plant, obs)
    assert "channel 'currents' value 2.5" in msg and "not A" in msg
    env.close()


@pytest.mark.parametrize("shape,n", [((2,), 2), ((2,), 1), ((3, 3), 3), ((), 1)])
def test_damping_of_another_shape_than_n_by_2_is_an_error(damping, shape, n):
    """A (n,) array was broadcast across the batch (each env got the others' command)."""
    plant, obs = damping
    msg = error(returning(lambda _: {"damping": np.zeros(shape)}), plant, obs, n)
    assert f"channel 'damping' has shape {shape}, expected ({n}, 2)" in msg
    assert "controller 'user'" in msg


def test_levitate_takes_n_or_n_by_1():
    env = make_env("RotorDrop-Relevitate-v1", command="discrete", **SHORT)
    plant, (obs, _) = Plant.from_env(env), env.reset(seed=0)
    for shape in ((2,), (2, 1)):
        a = act(returning(lambda n: {"levitate": np.ones(shape)}, needs=("levitate",)), plant, obs, 2)
        assert a.shape == (2,) and np.array_equal(a, [1, 1])
    assert "expected (2, 1) or (2,)" in error(
        returning(lambda n: {"levitate": np.ones((2, 2))}, needs=("levitate",)), plant, obs, 2)
    env.close()


def test_an_exception_in_commands_is_chained_into_one_line(damping):
    plant, obs = damping

    def broken(n):
        raise ZeroDivisionError("division by zero")
    with pytest.raises(ControllerError) as info:
        act(returning(broken), plant, obs)
    assert str(info.value) == ("controller 'user' (User): commands(obs) failed: "
                               "ZeroDivisionError: division by zero")
    assert isinstance(info.value.__cause__, ZeroDivisionError)


def test_commands_returning_none_is_named(damping):
    plant, obs = damping
    msg = error(returning(lambda n: None), plant, obs)
    assert "controller 'user' (User): commands() returned NoneType, expected a dict" in msg


def test_a_constructor_argument_without_default_is_named(damping):
    plant, _ = damping

    class Required(Controller):
        name = "required"

        def __init__(self, plant, level):
            super().__init__(plant)
    with pytest.raises(ControllerError, match=r"controller 'required' \(.*Required\): "
                                              r"Required\(plant\) failed: TypeError: .*'level'"):
        make_controller(Required, plant)


def test_a_reset_that_skips_the_base_reset_is_named(damping):
    plant, obs = damping

    class Forgetful(Controller):
        name = "forgetful"

        def reset(self, n, which=None):
            self.k = 0
    msg = error(Forgetful, plant, obs)
    assert "must call super().reset(n, which)" in msg


BAD_FILE = '''
from agents.control.controllers import Controller


class Typo(Controller):
    name = "typo"
    needs = ("damping",)

    def commands(self, obs):
        return {"dampnig": 1.0}
'''


def test_the_cli_reports_a_controller_bug_in_one_line(tmp_path, capsys):
    from agents.cli import main
    path = tmp_path / "bad.py"
    path.write_text(BAD_FILE)
    assert main(["evaluate", "--policy", f"{path}:Typo", "--env", "RotorDrop-Damping-v1",
                 "--episodes", "1", "--no-plots", "--out", str(tmp_path / "x")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("rotordrop evaluate: error: controller 'typo' (Typo):")
    assert "'dampnig'" in err and len(err.splitlines()) == 1


class Counter(Controller):
    """The common mistake: state set in __init__ only, so the second episode starts with the
    first one's count and switches the damper at another time."""
    name = "counter"
    needs = ("damping",)

    def __init__(self, plant):
        super().__init__(plant)
        self.k = 0

    def commands(self, obs):
        self.k += 1
        return {"damping": np.full((len(obs), 2), 1.0 if self.k > 20 else -1.0)}


class Stateful(Counter):
    """The contract: per-episode state (re)set in reset()."""

    def reset(self, n, which=None):
        super().reset(n, which)
        self.k = 0


@pytest.mark.parametrize("cls", [Counter, Stateful])
def test_identical_episodes_give_identical_kpis(cls):
    """Three runs of one scenario in one evaluation differed when state leaked."""
    kw = dict(overrides={"contact.friction": 0.3}, episode_time=0.03, terminate_on_failure=False)
    eps = run_episodes("RotorDrop-Damping-v1", lambda p: make_controller(cls, p), [0, 0, 0], kw,
                       record=True)
    for e in eps[1:]:
        assert e.kpis == eps[0].kpis
        np.testing.assert_array_equal(e.actions, eps[0].actions)
    assert eps[0].actions[:20].max() == -1.0 and eps[0].actions[20:].min() == 1.0


def test_one_controller_object_driven_by_hand_resets_its_state_at_episode_starts(damping):
    plant, obs = damping
    ctrl = make_controller(Stateful, plant)
    for _ in range(30):
        ctrl.predict(obs)
    first, _ = ctrl.predict(obs, episode_start=np.array([True]))
    assert ctrl.k == 1 and np.all(first == -1.0)


@pytest.mark.parametrize("env_id,kw", [("RotorDrop-Damping-v1", SHORT),
                                       ("RotorDrop-Relevitate-v1", dict(command="discrete", **SHORT)),
                                       ("RotorDrop-Full-v1", CONTINUOUS)])
def test_check_actor_passes_every_supported_baseline(env_id, kw):
    env = make_env(env_id, **kw)
    plant = Plant.from_env(env)
    env.close()
    for cls in BASELINES.values():
        if cls.supports(plant):
            check_actor(env_id, lambda p: make_controller(cls, p), kw)


@pytest.mark.parametrize("name", ["ppo-damping", "ppo-full"])
def test_check_actor_passes_shipped_policies(name):
    from agents.learning.policies import load_shipped
    policy = load_shipped(name)
    check_actor(policy.env_id, policy.bound, dict(policy.env_kwargs, **SHORT))


def test_check_controller_fails_fast_naming_the_controller(damping):
    plant, obs = damping
    bad = make_controller(returning(lambda n: {"damping": np.ones(2)}), plant)
    with pytest.raises(ControllerError, match=r"controller 'user' \(User\): channel 'damping' has shape"):
        check_controller(bad, plant, obs)
    with pytest.raises(ControllerError, match="'typo'"):
        check_actor("RotorDrop-Damping-v1", lambda p: make_controller(
            returning(lambda n: {"typo": 0}), p), SHORT)
    with pytest.raises(ValueError, match=r"obs has shape \(3,\)"):
        check_controller(make_controller(Passive, plant), plant, obs[:3])
