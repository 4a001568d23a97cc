"""``rotordrop train``: Stable-Baselines3 training on the batched rotor-drop environments.

One run writes into ``--out``:

===========================  ================================================================
``model.zip``                the final model (``ALGO.load``)
``vecnormalize.pkl``         the observation (and reward) normalisation statistics
``config.yaml``              the exact hyperparameters, env kwargs, seed and command used
``training.json``            wall time, steps/s, learning curve (evaluation reward and KPIs)
``learning_curve.png``       evaluation reward and backward-whirl rate against steps
``best/``                    the best model by evaluation reward, with its ``vecnormalize.pkl``
``checkpoints/``             periodic checkpoints (model, VecNormalize, replay buffer)
``eval/evaluations.npz``     ``EvalCallback`` log; ``tb/`` TensorBoard logs; ``monitor.csv``
===========================  ================================================================

``--resume DIR|CHECKPOINT.zip`` continues a run from its newest (or the given) checkpoint with
the statistics and replay buffer saved next to it.
"""
from __future__ import annotations

import json
import re
import shlex
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .hyperparams import ALGOS, ConfigError, dump_yaml, load_hyperparams, split

OFF_POLICY = ("sac", "td3")


@dataclass
class TrainResult:
    out: Path
    model_path: Path
    vecnormalize_path: Path
    timesteps: int
    wall_time_s: float


def _algo_class(algo: str):
    import stable_baselines3 as sb3
    return {"ppo": sb3.PPO, "sac": sb3.SAC, "td3": sb3.TD3}[algo]


def _callbacks():
    """SB3 callback classes, defined lazily so that importing this module stays light."""
    from stable_baselines3.common.callbacks import BaseCallback, EvalCallback

    from .rollout import final_kpis
    from .score import mean_finite

    class SaveVecNormalize(BaseCallback):
        """Saves the VecNormalize statistics next to the best model."""

        def __init__(self, path: Path):
            super().__init__()
            self.path = path

        def _on_step(self) -> bool:
            vn = self.model.get_vec_normalize_env()
            if vn is not None:
                vn.save(str(self.path))
            return True

    class KpiEvalCallback(EvalCallback):
        """EvalCallback that also records the episode KPIs (backward whirl, peak force...)."""

        def __init__(self, *args, eval_seed: int = 0, **kwargs):
            super().__init__(*args, **kwargs)
            self.eval_seed = eval_seed
            self.kpi_history: list[dict] = []
            self._kpis: list[dict] = []

        def _log_success_callback(self, locals_, globals_):
            super()._log_success_callback(locals_, globals_)
            if locals_["done"]:
                kpis = {k: float(v) for k, v in final_kpis(locals_["info"]).items()}
                kpis["failure"] = float(any(kpis.get(k, 0.0) for k in
                                            ("backward_whirl", "stator_contact", "bearing_overload")))
                self._kpis.append(kpis)

        def _on_step(self) -> bool:
            self._kpis = []
            if self.eval_freq > 0 and self.n_calls % self.eval_freq == 0:
                self.eval_env.seed(self.eval_seed)      # the same scenarios at every evaluation
            n_before = len(self.evaluations_timesteps)
            cont = super()._on_step()
            if len(self.evaluations_timesteps) > n_before:
                rewards = self.evaluations_results[-1]
                entry = dict(timesteps=int(self.num_timesteps), mean_reward=float(np.mean(rewards)),
                             std_reward=float(np.std(rewards)))
                for key in sorted({k for d in self._kpis for k in d}):
                    mean = mean_finite(d.get(key) for d in self._kpis)      # NaN (no value) skipped
                    if mean is not None:
                        entry[f"mean_{key}"] = mean
                        self.logger.record(f"eval/{key}", mean)
                self.kpi_history.append(entry)
            return cont

    class TqdmCallback(BaseCallback):
        """A tqdm progress bar over environment steps (no `rich` dependency)."""

        def __init__(self, total: int, eval_cb=None):
            super().__init__()
            self.total, self.eval_cb, self.bar = total, eval_cb, None

        def _on_training_start(self):
            from tqdm.auto import tqdm
            self.bar = tqdm(total=self.total, initial=self.model.num_timesteps, unit="step",
                            desc="train", dynamic_ncols=True, mininterval=1.0)

        def _on_step(self) -> bool:
            self.bar.update(self.training_env.num_envs)
            if self.eval_cb is not None and self.eval_cb.kpi_history and self.n_calls % 50 == 0:
                last = self.eval_cb.kpi_history[-1]
                extra = ({"validation": f"{last['validation_score']:.1f}"}
                         if "validation_score" in last else {})
                self.bar.set_postfix(eval_reward=f"{last['mean_reward']:.1f}",
                                     failure=f"{last.get('mean_failure', float('nan')):.2f}", **extra)
            return True

        def _on_training_end(self):
            self.bar.close()

    class ValidationCallback(BaseCallback):
        """At every evaluation, the benchmark score of the deterministic policy on the validation
        suite (:class:`agents.benchmark.Validator`); the best-scoring model goes to ``best/``
        with its VecNormalize statistics, and the score into the learning curve."""

        def __init__(self, env_id, algo, env_kwargs, meta, best_dir: Path, eval_cb):
            super().__init__()
            from .benchmark import Validator
            self.validator = Validator(env_id)
            self.env_id, self.algo, self.env_kwargs, self.meta = env_id, algo, env_kwargs, meta
            self.best_dir, self.eval_cb = best_dir, eval_cb
            self.best = -np.inf
            self.seen = 0

        def _on_step(self) -> bool:
            if len(self.eval_cb.kpi_history) == self.seen:
                return True
            self.seen = len(self.eval_cb.kpi_history)
            from .policies import LearnedPolicy
            vn = self.model.get_vec_normalize_env()
            pol = LearnedPolicy("candidate", self.algo, self.env_id, self.env_kwargs, self.model, vn)
            if self.meta.get("residual") is not None:
                pol.residual, pol.residual_scale = self.meta["residual"], self.meta["residual_scale"]
            score, _ = self.validator.score(pol.bound, self.env_kwargs)
            self.eval_cb.kpi_history[-1]["validation_score"] = score
            self.logger.record("eval/validation_score", score)
            if score > self.best:
                self.best = score
                self.model.save(str(self.best_dir / "best_model.zip"))
                if vn is not None:
                    vn.save(str(self.best_dir / "vecnormalize.pkl"))
            return True

    return SaveVecNormalize, KpiEvalCallback, TqdmCallback, ValidationCallback


def find_checkpoint(path: str | Path) -> tuple[Path, Path | None, Path | None]:
    """(model zip, VecNormalize pickle, replay buffer) of a checkpoint or a run directory's newest."""
    path = Path(path)
    if path.is_dir():
        ckpts = sorted((path / "checkpoints").glob("*_steps.zip") if (path / "checkpoints").is_dir()
                       else path.glob("*_steps.zip"), key=_steps_of)
        if not ckpts:
            raise FileNotFoundError(f"no checkpoint (*_steps.zip) in {path} or {path / 'checkpoints'}")
        path = ckpts[-1]
    if not path.is_file():
        raise FileNotFoundError(f"checkpoint {path} does not exist")
    steps = _steps_of(path)
    prefix = path.name[: path.name.rfind(f"_{steps}_steps")]
    vn = path.with_name(f"{prefix}_vecnormalize_{steps}_steps.pkl")
    rb = path.with_name(f"{prefix}_replay_buffer_{steps}_steps.pkl")
    return path, (vn if vn.is_file() else None), (rb if rb.is_file() else None)


def _steps_of(p: Path) -> int:
    m = re.search(r"_(\d+)_steps\.zip$", p.name)
    return int(m.group(1)) if m else -1


def resolve_config(env_id: str, algo: str, config=None, timesteps=None, n_envs=None) -> dict:
    hp = load_hyperparams(algo, env_id, config)
    if timesteps is not None:
        hp["n_timesteps"] = int(timesteps)
    if n_envs is not None:
        hp["n_envs"] = int(n_envs)
    return hp


def train(env_id: str, algo: str, out: str | Path, timesteps: int | None = None,
          n_envs: int | None = None, config: str | Path | None = None, seed: int = 0,
          resume: str | Path | None = None, threads: int = 1, progress: bool = True,
          verbose: int = 0, command: str | None = None) -> TrainResult:
    """Train ``algo`` on ``env_id`` and save model, statistics, config and learning curve."""
    if algo not in ALGOS:
        raise ConfigError(f"--algo must be one of {', '.join(ALGOS)}, got {algo!r}")
    from stable_baselines3.common.callbacks import CallbackList, CheckpointCallback
    from stable_baselines3.common.vec_env import VecNormalize

    from .plant import make_vec_env

    set_threads(threads)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    hp = resolve_config(env_id, algo, config, timesteps, n_envs)
    meta, algo_kwargs = split(hp)
    total = meta.get("n_timesteps", 100_000)
    n = meta.get("n_envs", 1)
    env_kwargs = dict(meta.get("env_kwargs") or {})
    Algo = _algo_class(algo)
    if algo in OFF_POLICY and env_id.endswith("Relevitate-v0") and env_kwargs.get("command") == "discrete":
        raise ConfigError(f"{algo} needs continuous actions: set env_kwargs.command = continuous")

    rw = dict(reward=meta["reward"], reward_kwargs=meta["reward_kwargs"],
              residual=meta.get("residual"), residual_scale=meta.get("residual_scale"))
    venv = make_vec_env(env_id, n, seed, env_kwargs, monitor_file=out / "monitor.csv", **rw)
    eval_venv = make_vec_env(env_id, 1, seed + 10_000, env_kwargs, **rw)
    norm = meta["normalize"]
    norm_kwargs = norm if isinstance(norm, dict) else {}
    if resume is not None:
        ckpt, vn_path, rb_path = find_checkpoint(resume)
        if norm is not False:
            if vn_path is None:
                raise FileNotFoundError(f"checkpoint {ckpt} has no VecNormalize statistics next to it")
            venv = VecNormalize.load(str(vn_path), venv)
            venv.training = True
        model = Algo.load(str(ckpt), env=venv, device="cpu", tensorboard_log=str(out / "tb"),
                          verbose=verbose)
        if rb_path is not None and algo in OFF_POLICY:
            model.load_replay_buffer(str(rb_path))
        remaining = max(0, total - model.num_timesteps)
        print(f"resuming from {ckpt} at {model.num_timesteps} steps; {remaining} to go")
    else:
        if norm is not False:
            venv = VecNormalize(venv, **norm_kwargs)
        if algo == "td3" and "noise_type" in meta:
            algo_kwargs["action_noise"] = _action_noise(meta, venv.action_space.shape[0])
        model = Algo(meta.get("policy", "MlpPolicy"), venv, seed=seed, device="cpu",
                     tensorboard_log=str(out / "tb"), verbose=verbose, **algo_kwargs)
        remaining = total
    if norm is not False:
        eval_venv = VecNormalize(eval_venv, training=False, norm_reward=False,
                                 **{k: v for k, v in norm_kwargs.items()
                                    if k not in ("norm_reward", "training")})

    SaveVecNormalize, KpiEvalCallback, TqdmCallback, ValidationCallback = _callbacks()
    (out / "best").mkdir(exist_ok=True)
    eval_cb = KpiEvalCallback(
        eval_venv, n_eval_episodes=meta.get("n_eval_episodes", 5),
        eval_freq=max(meta.get("eval_freq", 10_000) // n, 1) if meta.get("eval_freq", 1) else -1,
        best_model_save_path=None if meta["validation"] else str(out / "best"),
        log_path=str(out / "eval"), deterministic=True, verbose=0,
        callback_on_new_best=None if meta["validation"] else SaveVecNormalize(out / "best" / "vecnormalize.pkl"),
        eval_seed=seed + 10_000)
    cbs = [eval_cb]
    if meta["validation"]:
        cbs.append(ValidationCallback(env_id, algo, env_kwargs, meta, out / "best", eval_cb))
    if meta.get("checkpoint_freq", 0):
        cbs.append(CheckpointCallback(save_freq=max(meta["checkpoint_freq"] // n, 1),
                                      save_path=str(out / "checkpoints"), name_prefix="rl_model",
                                      save_vecnormalize=True, save_replay_buffer=algo in OFF_POLICY))
    if progress:
        cbs.append(TqdmCallback(total, eval_cb))

    record = dict(algo=algo, env_id=env_id, seed=seed, threads=threads,
                  command=command or f"rotordrop train --env {env_id} --algo {algo} --seed {seed}",
                  resumed_from=str(resume) if resume else None, hyperparams=hp,
                  versions=_versions())
    dump_yaml(record, out / "config.yaml")
    t0 = time.perf_counter()
    model.learn(total_timesteps=remaining, callback=CallbackList(cbs), tb_log_name=algo,
                reset_num_timesteps=resume is None, progress_bar=False)
    wall = time.perf_counter() - t0
    model_path = out / "model.zip"
    vn_path = out / "vecnormalize.pkl"
    model.save(str(model_path))
    if model.get_vec_normalize_env() is not None:
        model.get_vec_normalize_env().save(str(vn_path))
    summary = dict(record, timesteps=int(model.num_timesteps), wall_time_s=wall,
                   steps_per_s=remaining / wall if wall > 0 else None,
                   learning_curve=eval_cb.kpi_history)
    (out / "training.json").write_text(json.dumps(summary, indent=2, default=str))
    from .plots import plot_learning_curve
    plot_learning_curve(eval_cb.kpi_history, out / "learning_curve.png", f"{algo} {env_id}")
    venv.close()
    eval_venv.close()
    return TrainResult(out, model_path, vn_path, int(model.num_timesteps), wall)


def set_threads(threads: int) -> None:
    """torch and numba threads. One each is several times faster for these small networks and
    the batched physics step on a few shared cores (numba's OpenMP threads oversubscribe)."""
    import numba
    import torch
    n = max(1, int(threads))
    torch.set_num_threads(n)
    numba.set_num_threads(min(n, numba.config.NUMBA_NUM_THREADS))


def _action_noise(meta: dict, dim: int):
    from stable_baselines3.common.noise import NormalActionNoise, OrnsteinUhlenbeckActionNoise
    std = float(meta.get("noise_std", 0.1)) * np.ones(dim)
    kind = meta["noise_type"]
    if kind == "normal":
        return NormalActionNoise(np.zeros(dim), std)
    if kind == "ornstein-uhlenbeck":
        return OrnsteinUhlenbeckActionNoise(np.zeros(dim), std)
    raise ConfigError(f"noise_type must be normal or ornstein-uhlenbeck, got {kind!r}")


def _versions() -> dict:
    import gymnasium
    import stable_baselines3
    import torch
    return dict(python=sys.version.split()[0], stable_baselines3=str(stable_baselines3.__version__),
                torch=str(torch.__version__), gymnasium=str(gymnasium.__version__),
                numpy=str(np.__version__))


def command_line(argv: list[str] | None = None) -> str:
    return "rotordrop " + " ".join(shlex.quote(a) for a in (argv if argv is not None else sys.argv[1:]))
