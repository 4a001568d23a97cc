"""``rotordrop train --seeds 0,1,2``: one training run per seed, side by side.

Each seed trains into ``<out>/seed_<k>`` exactly as ``rotordrop train --seed k --out
<out>/seed_<k>`` would (:func:`agents.training.train.train`). On ``--backend local`` the seeds run one
after the other in this process; on ``--backend ray`` each seed is one Ray task holding
``--threads`` CPUs (``num_cpus``), so a cluster trains them at once. A task carries only the
training's arguments (env id, algorithm, paths, numbers); it writes its run on the node that ran
it, so on a multi-machine cluster ``--out`` must be a filesystem every node shares. The
configuration is checked here before any task starts.
"""
from __future__ import annotations

from pathlib import Path

from physics.runs.backend import Backend

from .train import TrainResult, resolve_config, train


def parse_seeds(text: str) -> list[int]:
    """``"0,1,2"`` -> [0, 1, 2] (distinct integers >= 0)."""
    try:
        seeds = [int(s) for s in text.split(",") if s.strip()]
    except ValueError:
        seeds = []
    if not seeds or any(s < 0 for s in seeds) or len(set(seeds)) != len(seeds):
        raise ValueError(f"--seeds expects distinct integers >= 0 separated by commas, got {text!r}")
    return seeds


def seed_dir(out: str | Path, seed: int) -> Path:
    return Path(out) / f"seed_{seed}"


def train_seeds(seeds: list[int], env_id: str, algo: str, outs: list[str | Path],
                backend: Backend = Backend(), threads: int = 1, progress: bool = True,
                **kwargs) -> list[TrainResult]:
    """Train seed ``seeds[i]`` into ``outs[i]`` on ``backend`` (module doc); results in the
    order of ``seeds``."""
    from ..learning.hyperparams import check_sb3, split
    meta, algo_kwargs = split(resolve_config(env_id, algo, kwargs.get("config"),
                                             kwargs.get("timesteps"), kwargs.get("n_envs")))
    check_sb3(algo, env_id, meta, algo_kwargs)                # fail before any task starts
    tasks = [(dict(kwargs, env_id=env_id, algo=algo, out=str(o), seed=s, threads=threads,
                   progress=progress and backend.name == "local"),) for s, o in zip(seeds, outs)]
    from tqdm.auto import tqdm
    results: dict[int, TrainResult] = {}
    with backend.session() as session, tqdm(total=len(seeds), desc="seeds", unit="run",
                                            disable=not progress or backend.name == "local") as bar:
        for i, result in session.imap(train_task, tasks, num_cpus=threads):
            results[i] = result
            bar.update(1)
    return [results[i] for i in range(len(seeds))]


def train_task(kwargs: dict) -> TrainResult:
    """One seed's training (the body of a Ray task)."""
    return train(**kwargs)
