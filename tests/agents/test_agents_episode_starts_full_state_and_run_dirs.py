"""Agents across episodes and observations: a controller finds episode starts without the caller,
policies trained on the full state evaluate, rl-zoo3's ``train_freq: [1, episode]`` and a run's
``best/`` directory as ``--policy``."""
import numpy as np
import pytest

from agents.control.controllers import Controller, make_baseline
from agents.learning.hyperparams import ConfigError, algo_class, split
from agents.control.plant import ControllerError, Plant, make_env
from agents.benchmarking.rollout import run_episodes

SHORT = dict(episode_time=0.03, terminate_on_failure=False)
WHIRL = dict(overrides={"contact.friction": 0.45}, **SHORT)


class Latch(Controller):
    """C_max from the first time the rotor leaves the centre by 10 % of the clearance."""
    name = "latch"
    needs = ("damping",)

    def reset(self, n, which=None):
        super().reset(n, which)
        if which is None:
            self.latched = np.zeros(n, dtype=bool)
        else:
            self.latched[which] = False

    def commands(self, obs):
        p = self.plant
        self.latched |= np.hypot(p.get(obs, "x1"), p.get(obs, "y1")) > 0.1 * p.clearance
        return {"damping": np.where(self.latched[:, None], 1.0, self.hold)}


def _docs_loop(env, ctrl, seed=0):
    """The loop of docs/agents.md "Controllers": no episode_start. (actions, peak force)."""
    obs, _ = env.reset(seed=seed)
    done, actions = False, []
    while not done:
        action, _ = ctrl.predict(obs)
        actions.append(np.array(action, dtype=float))
        obs, _, term, trunc, info = env.step(action)
        done = term or trunc
    return np.array(actions), info["kpi_peak_contact_force_N"]


# ---------------------------------------------------------------- 1. episode starts --
@pytest.mark.parametrize("name,env_id,kw", [
    ("whirl-switch", "RotorDrop-Damping-v1", {}),
    ("pid-relevitate", "RotorDrop-Relevitate-v1", dict(command="continuous", power_return_time=0.005))])
def test_one_controller_runs_identical_episodes_identically_without_episode_start(name, env_id, kw):
    env = make_env(env_id, **WHIRL, **kw)
    ctrl = make_baseline(name, Plant.from_env(env))
    first, f1 = _docs_loop(env, ctrl)
    t1 = ctrl.t.copy()
    second, f2 = _docs_loop(env, ctrl)
    env.close()
    np.testing.assert_array_equal(second, first)
    assert f2 == f1
    np.testing.assert_allclose(ctrl.t, t1)              # episode 2 restarted the clock (0.03 s)
    np.testing.assert_allclose(t1, 0.03, rtol=1e-9)


def test_a_users_stateful_controller_starts_episode_two_unlatched():
    env = make_env("RotorDrop-Damping-v1", **WHIRL)
    ctrl = Latch(Plant.from_env(env))
    first, _ = _docs_loop(env, ctrl)
    assert first[0].max() < 1.0 and first[-1].min() == 1.0          # it latched in episode 1
    second, _ = _docs_loop(env, ctrl)
    env.close()
    np.testing.assert_array_equal(second, first)


def test_one_step_episodes_each_start_afresh():
    """The time observation is 0 again: a new episode even if it did not go below the last."""
    env = make_env("RotorDrop-Damping-v1", episode_time=1e-3, terminate_on_failure=False)
    ctrl = make_baseline("whirl-switch", Plant.from_env(env))
    for _ in range(3):
        actions, _ = _docs_loop(env, ctrl)
        assert len(actions) == 1
        np.testing.assert_allclose(ctrl.t, [1e-3])
    env.close()


def test_batch_rows_reset_where_their_time_goes_back_and_sb3_flags_still_work():
    env = make_env("RotorDrop-Damping-v1", **WHIRL)
    plant = Plant.from_env(env)
    obs = [env.reset(seed=0)[0]]
    for _ in range(10):
        obs.append(env.step(env.action_space.sample())[0])
    env.close()
    ctrl = make_baseline("whirl-switch", plant)
    for k in range(8):                                  # both rows run 8 steps
        ctrl.predict(np.stack([obs[k], obs[k]]))
    ctrl.predict(np.stack([obs[8], obs[2]]))            # row 1: time went back to 2 ms
    np.testing.assert_allclose(ctrl.t, [9e-3, 1e-3])
    ctrl.predict(np.stack([obs[9], obs[9]]))            # the same time twice: no new episode
    ctrl.predict(np.stack([obs[9], obs[9]]))
    np.testing.assert_allclose(ctrl.t, [11e-3, 3e-3])
    ctrl.predict(np.stack([obs[10], obs[10]]), episode_start=np.array([True, False]))
    np.testing.assert_allclose(ctrl.t, [1e-3, 4e-3])


# ------------------------------------------------------------------ 2. full state --
FULL = dict(full_state=True, **WHIRL)


def test_a_full_state_env_has_a_plant_but_sensor_controllers_are_refused_by_name():
    env = make_env("RotorDrop-Damping-v1", **FULL)
    plant = Plant.from_env(env)
    env.close()
    with pytest.raises(ControllerError, match=r"controller 'whirl-switch' \(WhirlSwitch\) needs the "
                                              r"sensor observations x1, .*full_state=True"):
        make_baseline("whirl-switch", plant)
    for name in ("passive", "max-damping"):
        make_baseline(name, plant)


def test_passive_on_the_full_state_is_the_passive_drop_and_records_the_sensor_orbit():
    eps = [run_episodes("RotorDrop-Damping-v1", lambda p: make_baseline("passive", p), [3],
                        dict(WHIRL, full_state=fs, randomize=True), record=True)[0]
           for fs in (False, True)]
    sensor, full = eps
    assert full.kpis == sensor.kpis                      # damper held at C_s, read from RB1.Cs
    np.testing.assert_array_equal(full.actions, sensor.actions)
    for name in ("x1", "y1", "x2", "y2"):
        np.testing.assert_allclose(full.obs[:, list(full.obs_names).index(name)],
                                   sensor.obs[:, list(sensor.obs_names).index(name)],
                                   rtol=1e-6, atol=1e-12)


def _save_policy(path, env_id, env_kwargs, algo="td3", best=False):
    """A freshly initialised SB3 model saved as ``rotordrop train`` would (its config.yaml)."""
    from agents.learning.hyperparams import dump_yaml
    env = make_env(env_id, **env_kwargs)
    model = algo_class(algo)("MlpPolicy", env, seed=0, device="cpu", learning_starts=0)
    env.close()
    (path / "best").mkdir(parents=True, exist_ok=True)
    model.save(str(path / "best" / "best_model.zip" if best else path / "model.zip"))
    dump_yaml(dict(algo=algo, env_id=env_id,
                   hyperparams=dict(normalize=False, env_kwargs=dict(env_kwargs))),
              path / "config.yaml")
    return model


def test_a_policy_trained_on_the_full_state_is_evaluated_against_passive(tmp_path):
    from agents.benchmarking.evaluate import evaluate
    _save_policy(tmp_path / "run", "RotorDrop-Damping-v1", dict(full_state=True))
    report = evaluate(str(tmp_path / "run"), None, 1, tmp_path / "ev", env_kwargs=dict(WHIRL),
                      randomize=False)
    assert report["env_kwargs"]["full_state"] is True
    assert report["passive_summary"]["episodes"] == 1
    assert "orbits.png" in report["figures"] and (tmp_path / "ev" / "orbits.png").is_file()


def test_a_residual_on_a_sensor_controller_refuses_full_state_training():
    from agents.training.train import check_env
    meta, _ = split(dict(residual="whirl-switch", env_kwargs=dict(full_state=True)))
    with pytest.raises(ConfigError, match="residual: .*needs the sensor observations.*full_state"):
        check_env("RotorDrop-Damping-v1", "td3", meta)


# ---------------------------------------------------------- 3. train_freq as a list --
def test_train_freq_list_becomes_sb3s_tuple_as_in_rl_zoo3():
    meta, kwargs = split({"train_freq": [1, "episode"], "n_envs": 1, "learning_starts": 0})
    assert kwargs["train_freq"] == (1, "episode")
    env = make_env("RotorDrop-Damping-v1", **SHORT)
    model = algo_class("td3")("MlpPolicy", env, device="cpu", **kwargs)
    env.close()
    assert (model.train_freq.frequency, model.train_freq.unit.value) == (1, "episode")


def test_train_freq_per_episode_with_several_envs_is_refused_naming_n_envs():
    with pytest.raises(ConfigError, match=r"train_freq \[1, 'episode'\].*needs n_envs: 1.*got n_envs 4"):
        split({"train_freq": [1, "episode"], "n_envs": 4})


# ------------------------------------------------------------ 4. a run's best/ dir --
def test_a_runs_best_directory_loads_as_a_policy(tmp_path):
    """``--policy RUN/best``: best_model.zip and vecnormalize.pkl there, config.yaml in RUN."""
    from stable_baselines3.common.vec_env import DummyVecEnv, VecNormalize
    from agents.learning.policies import LearnedPolicy
    model = _save_policy(tmp_path, "RotorDrop-Damping-v1", SHORT, best=True)
    vn = VecNormalize(DummyVecEnv([lambda: make_env("RotorDrop-Damping-v1", **SHORT)]))
    vn.obs_rms.mean[:] = 0.5
    vn.save(str(tmp_path / "best" / "vecnormalize.pkl"))
    pol = LearnedPolicy.load(tmp_path / "best")
    assert pol.env_id == "RotorDrop-Damping-v1" and pol.algo == "td3"
    obs = np.linspace(-1.0, 1.0, 14, dtype=np.float32)
    np.testing.assert_array_equal(pol.predict(obs)[0],
                                  model.predict(vn.normalize_obs(obs), deterministic=True)[0])
    with pytest.raises(FileNotFoundError, match="no model at .*model.zip .*best_model.zip"):
        LearnedPolicy.load(tmp_path)
