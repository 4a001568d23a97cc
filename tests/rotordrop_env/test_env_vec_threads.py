"""The batched VecEnv's thread choice: one thread for a few environments, the faster of one and
several threads by timing otherwise, and the same numbers whatever it chose."""
import numpy as np

from rotordrop_env import make_batched
from rotordrop_env.vec_env import (ENVS_PER_THREAD, RECHOOSE_EVERY, TRIAL_STEPS, ThreadChoice,
                                   auto_threads)


def _drive(choice: ThreadChoice, seconds: dict, steps: int) -> list[int]:
    used = []
    for _ in range(steps):
        n = choice.next()
        used.append(n)
        choice.record(n, seconds[n])
    return used


def test_the_faster_thread_count_wins_and_is_chosen_again_later():
    choice = ThreadChoice(2)
    used = _drive(choice, {1: 2e-3, 2: 1e-3}, 2 * TRIAL_STEPS + 10)
    assert used[:2 * TRIAL_STEPS] == [1] * TRIAL_STEPS + [2] * TRIAL_STEPS      # the trials
    assert used[2 * TRIAL_STEPS:] == [2] * 10 and choice.chosen == 2
    # a machine that got busy: after RECHOOSE_EVERY steps one thread is tried again and wins
    used = _drive(choice, {1: 2e-3, 2: 5e-3}, RECHOOSE_EVERY - 10 + 2 * TRIAL_STEPS + 5)
    assert used[-5:] == [1] * 5 and choice.chosen == 1


def test_few_environments_run_on_one_thread_without_trials():
    assert auto_threads(1) == 1 and auto_threads(ENVS_PER_THREAD - 1) == 1
    choice = ThreadChoice(auto_threads(1))
    assert _drive(choice, {1: 1.0}, 3 * TRIAL_STEPS) == [1] * (3 * TRIAL_STEPS)


def test_default_threads_step_exactly_like_one_thread():
    kw = dict(episode_time=0.02, overrides={"contact.friction": 0.5})
    n = 2 * ENVS_PER_THREAD
    auto = make_batched("RotorDrop-Damping-v1", n, seed=3, **kw)
    one = make_batched("RotorDrop-Damping-v1", n, seed=3, n_threads=1, **kw)
    rng = np.random.default_rng(0)
    obs_a, obs_o = auto.reset(), one.reset()
    for _ in range(2 * TRIAL_STEPS + 4):            # through the trials of both candidates
        a = rng.uniform(-1, 1, (n,) + auto.action_space.shape).astype(np.float32)
        obs_a, rew_a, done_a, _ = auto.step(a)
        obs_o, rew_o, done_o, _ = one.step(a)
        assert np.array_equal(obs_a, obs_o) and np.array_equal(rew_a, rew_o)
        assert np.array_equal(done_a, done_o)
    assert np.any(rew_a != 0.0)
