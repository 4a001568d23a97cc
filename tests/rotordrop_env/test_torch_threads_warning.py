"""The SB3 VecEnv warns once per process when torch trains on several threads (a plain-SB3 user
who did not call torch.set_num_threads(1)); one thread, or a thread count rotordrop train chose
(--threads), is quiet; the environments themselves never warn."""
import warnings

import gymnasium as gym
import pytest
import torch

import rotordrop_env
from rotordrop_env import vec_env


@pytest.fixture
def threads(monkeypatch):
    import numba
    before, numba_before = torch.get_num_threads(), numba.get_num_threads()
    monkeypatch.setattr(vec_env, "_warned_threads", False)
    monkeypatch.setattr(vec_env, "TORCH_THREADS_QUIET", 1)
    yield torch.set_num_threads
    torch.set_num_threads(before)
    numba.set_num_threads(numba_before)


def test_several_torch_threads_warn_once(threads):
    threads(2)
    with pytest.warns(vec_env.TorchThreadsWarning, match="set_num_threads"):
        rotordrop_env.make_batched("RotorDrop-Damping-v1", n_envs=1, seed=0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        rotordrop_env.make_batched("RotorDrop-Damping-v1", n_envs=1, seed=0)   # once only
        gym.make("RotorDrop-Damping-v1")                                          # never the env


def test_one_thread_or_a_chosen_count_is_quiet(threads):
    from agents.training.train import set_threads
    threads(1)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        rotordrop_env.make_batched("RotorDrop-Damping-v1", n_envs=1, seed=0)
        set_threads(2)                                  # rotordrop train --threads 2
        rotordrop_env.make_batched("RotorDrop-Damping-v1", n_envs=1, seed=0)
    assert not vec_env._warned_threads
