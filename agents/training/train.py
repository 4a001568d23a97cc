"""``rotordrop train``: Stable-Baselines3 training on the batched rotor-drop environments.

One run writes into ``--out``:

===========================  ================================================================
``model.zip``                the final model, self-contained: ``ALGO.load`` + ``predict`` runs it
                             as ``rotordrop evaluate`` does (normalisation, residual inside)
``vecnormalize.pkl``         the observation (and reward) normalisation statistics
``config.yaml``              the exact hyperparameters, env kwargs, seed and command used
``training.json``            wall time, steps/s, learning curve (evaluation reward and KPIs)
``learning_curve.png``       evaluation reward and backward-whirl rate against steps
``best/``                    the best model by evaluation reward (self-contained), with its
                             ``vecnormalize.pkl``
``checkpoints/``             periodic checkpoints (model, VecNormalize, replay buffer)
``eval/evaluations.npz``     ``EvalCallback`` log; ``tb/`` TensorBoard logs; ``monitor.csv``
===========================  ================================================================

``--resume DIR|CHECKPOINT.zip`` continues a run from its newest (or the given) checkpoint with
the statistics and replay buffer saved next to it. Resumed into its own directory
(``--resume R --out R``) the run's record continues: the learning curve and
``eval/evaluations.npz`` keep their entries, ``monitor.csv`` is appended to and ``best/`` is only
replaced by a model that beats the best score recorded so far. Any other ``--out`` must be new or
hold no run unless ``overwrite`` (``--overwrite``) removes the run in it.

The final model is always evaluated (and checkpointed, with ``checkpoint_freq`` > 0) unless the
last step already was an evaluation (a checkpoint), so a run shorter than ``eval_freq`` still
writes ``best/`` and its learning curve. Every input is checked before anything is written: a
bad key or value raises :class:`~agents.learning.hyperparams.ConfigError` naming it.
"""
from __future__ import annotations

import json
import re
import shlex
import shutil
import sys
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..learning.hyperparams import (ALGOS, ConfigError, algo_class, check_sb3, dump_yaml, load_hyperparams,
                          read_yaml, split)

OFF_POLICY = ("sac", "td3", "tqc", "crossq")
#: what a run writes into --out (a directory holding one of them holds a run)
RUN_FILES = ("model.zip", "vecnormalize.pkl", "config.yaml", "training.json", "learning_curve.png",
             "monitor.csv", "best", "checkpoints", "eval", "tb")


@dataclass
class TrainResult:
    out: Path
    model_path: Path
    vecnormalize_path: Path
    timesteps: int
    wall_time_s: float
    files: list[str] = field(default_factory=list)      # written, relative to ``out``
    evaluations: int = 0                                  # evaluations in this session

    def summary(self) -> str:
        """The CLI's line: steps, time, every file written (and why best/ is missing)."""
        line = (f"trained {self.timesteps} steps in {self.wall_time_s:.0f} s; wrote "
                + ", ".join(str(self.out / f) for f in self.files))
        if not self.evaluations:
            line += "; no evaluation ran (eval_freq: 0, or no steps to go): no best/ model"
        return line


def save_policy(model, path: Path, env_id: str, meta: dict) -> None:
    """``model`` at ``path`` as a self-contained zip that plain SB3 runs like ``rotordrop
    evaluate`` (:func:`agents.sb3_policy.export_self_contained`), and its VecNormalize statistics
    as ``vecnormalize.pkl`` next to it (for rl-zoo3 and to continue training)."""
    from ..sb3_policy import export_self_contained
    vn = model.get_vec_normalize_env()
    export_self_contained(model, vn, path, env_id=env_id, env_kwargs=meta["env_kwargs"],
                          residual=meta.get("residual"), residual_scale=meta.get("residual_scale"),
                          frame_stack=meta.get("frame_stack", 1))
    if vn is not None:
        vn.save(str(Path(path).parent / "vecnormalize.pkl"))


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


def resolve_config(env_id: str, algo: str, config=None, timesteps=None, n_envs=None,
                   **run: int | None) -> dict:
    """The hyperparameters with the command line's overrides (``run``: ``eval_freq``,
    ``n_eval_episodes``, ``checkpoint_freq``; None keeps the config's), a residual's
    ``{law, tuned_on}`` replaced by the tuned constants themselves (``{law, gains}``)."""
    hp = load_hyperparams(algo, env_id, config)
    spec = hp.get("residual")
    if isinstance(spec, dict) and set(spec) == {"law", "tuned_on"}:
        from ..benchmarking.tuned import tuned_spec        # the run keeps the numbers
        try:
            hp["residual"] = tuned_spec(spec["law"], spec["tuned_on"])
        except ValueError as exc:
            raise ConfigError(f"residual: {exc}") from exc
    if timesteps is not None:
        hp["n_timesteps"] = int(timesteps)
    if n_envs is not None:
        hp["n_envs"] = int(n_envs)
    hp.update({k: int(v) for k, v in run.items() if v is not None})
    return hp


def train(env_id: str, algo: str, out: str | Path, timesteps: int | None = None,
          n_envs: int | None = None, config: str | Path | None = None, seed: int = 0,
          resume: str | Path | None = None, threads: int = 1, progress: bool = True,
          verbose: int = 0, command: str | None = None, overwrite: bool = False,
          eval_freq: int | None = None, n_eval_episodes: int | None = None,
          checkpoint_freq: int | None = None, time_limit: float | None = None) -> TrainResult:
    """Train ``algo`` on ``env_id`` and save model, statistics, config and learning curve
    (module docstring: resuming, an existing ``out``, the final evaluation). ``time_limit``
    [s of wall-clock time]: stop training once it has passed (the run then ends as at its last
    step: final evaluation, ``best/``, model, ``training.json`` with ``stopped_by_time_limit``)."""
    if algo not in ALGOS:
        raise ConfigError(f"--algo must be one of {', '.join(ALGOS)}, got {algo!r}")
    if time_limit is not None and not (np.isfinite(time_limit) and time_limit > 0):
        raise ConfigError(f"--time-limit must be a number of seconds > 0, got {time_limit}")
    if int(threads) < 1:
        raise ConfigError(f"--threads must be >= 1, got {threads}")
    from stable_baselines3.common.callbacks import CallbackList

    out = Path(out)
    hp = resolve_config(env_id, algo, config, timesteps, n_envs, eval_freq=eval_freq,
                        n_eval_episodes=n_eval_episodes, checkpoint_freq=checkpoint_freq)
    meta, algo_kwargs = split(hp)
    check_sb3(algo, env_id, meta, algo_kwargs)
    ckpt = find_checkpoint(resume) if resume is not None else None
    if ckpt is not None:
        _check_resumed_run(ckpt[0], algo, env_id)
    continuing = ckpt is not None and run_dir(ckpt[0]).resolve() == out.resolve()
    held = _held_run(out, continuing, overwrite)
    curve, eval_log = (_previous_record(out, meta.get("n_eval_episodes", 5)) if continuing
                       else ([], {}))
    check_env(env_id, algo, meta)
    set_threads(threads)
    total = meta.get("n_timesteps", 100_000)
    monitor, eval_venv, model = _build(env_id, algo, meta, algo_kwargs, seed, ckpt, out, verbose)
    remaining = max(0, total - model.num_timesteps)
    if ckpt is not None:
        print(f"resuming from {ckpt[0]} at {model.num_timesteps} steps; {remaining} to go")

    _remove(out, held)
    out.mkdir(parents=True, exist_ok=True)
    _log_episodes(monitor, out / "monitor.csv", env_id, append=continuing)
    record = dict(algo=algo, env_id=env_id, seed=seed, threads=threads, time_limit_s=time_limit,
                  command=command or f"rotordrop train --env {env_id} --algo {algo} --seed {seed}",
                  resumed_from=str(ckpt[0]) if ckpt else None, hyperparams=hp,
                  versions=_versions())
    dump_yaml(record, out / "config.yaml")

    eval_cb, record_cb, cbs = _training_callbacks(env_id, algo, meta, seed, out, eval_venv, record,
                                                  curve, eval_log, total if progress else None,
                                                  time_limit)
    model.learn(total_timesteps=remaining, callback=CallbackList(cbs), tb_log_name=algo,
                reset_num_timesteps=ckpt is None, progress_bar=False)
    model_path = out / "model.zip"
    vn_path = out / "vecnormalize.pkl"
    save_policy(model, model_path, env_id, meta)
    wall = record_cb.write(finished=True)
    from ..benchmarking.plots import plot_learning_curve
    plot_learning_curve(sorted(eval_cb.kpi_history, key=lambda h: h["timesteps"]),
                        out / "learning_curve.png", f"{algo} {env_id}")
    model.get_env().close()
    eval_venv.close()
    return TrainResult(out, model_path, vn_path, int(model.num_timesteps), wall, _written(out),
                       len(eval_cb.kpi_history) - len(curve))


def _build(env_id: str, algo: str, meta: dict, algo_kwargs: dict, seed: int, ckpt, out: Path,
           verbose: int):
    """(training env's VecMonitor, evaluation env, model): a new one, or the checkpoint's.
    Nothing is written yet: the monitor's log is attached once ``out`` is ready."""
    from .training_env import make_vec_env
    rw = dict(reward=meta["reward"], reward_kwargs=meta["reward_kwargs"],
              residual=meta.get("residual"), residual_scale=meta.get("residual_scale"))
    monitor = make_vec_env(env_id, meta.get("n_envs", 1), seed, meta["env_kwargs"], **rw)
    stack = meta.get("frame_stack", 1)
    eval_venv = _eval_env(_stacked(make_vec_env(env_id, 1, seed + 10_000, meta["env_kwargs"],
                                                **rw), stack), meta["normalize"])
    if ckpt is not None:
        model = _resumed_model(algo, env_id, ckpt, meta["normalize"], _stacked(monitor, stack),
                               out, verbose)
    else:
        model = _new_model(algo, meta, algo_kwargs,
                           _train_env(_stacked(monitor, stack), meta["normalize"]), seed, out,
                           verbose)
    return monitor, eval_venv, model


def _training_callbacks(env_id: str, algo: str, meta: dict, seed: int, out: Path, eval_venv,
                        record: dict, curve: list[dict], eval_log: dict, progress_total: int | None,
                        time_limit: float | None = None):
    """(evaluation, record, all callbacks): evaluation with KPIs continuing ``curve`` and
    ``eval_log`` from their best score, validation, checkpoints, progress bar, training.json,
    the wall-clock limit."""
    from .callbacks import (FinalCheckpoint, KpiEvalCallback, RecordCallback, SaveBest,
                            TqdmCallback, WallClockLimit)
    from .validation import ValidationCallback
    n = meta.get("n_envs", 1)
    eval_freq = max(meta.get("eval_freq", 10_000) // n, 1) if meta.get("eval_freq", 1) else -1
    keep_best = eval_freq > 0 and not meta["validation"]      # else ValidationCallback keeps it
    save = lambda model, path: save_policy(model, path, env_id, meta)     # noqa: E731
    eval_cb = KpiEvalCallback(
        eval_venv, n_eval_episodes=meta.get("n_eval_episodes", 5), eval_freq=eval_freq,
        best_model_save_path=str(out / "best") if keep_best else None,
        log_path=str(out / "eval") if eval_freq > 0 else None, deterministic=True, verbose=0,
        callback_on_new_best=SaveBest(out / "best", save) if keep_best else None,
        eval_seed=seed + 10_000)
    eval_cb.kpi_history = list(curve)
    for key, values in eval_log.items():
        setattr(eval_cb, key, values)
    eval_cb.best_mean_reward = _best(curve, "mean_reward")
    cbs = [eval_cb]
    if "action_log_std" in meta:
        from ..learning.exploration import ActionSpread
        cbs.insert(0, ActionSpread(meta["action_log_std"]))
    if meta["validation"]:
        policy = dict(env_id=env_id, algo=algo, env_kwargs=meta["env_kwargs"],
                      residual=meta.get("residual"), residual_scale=meta.get("residual_scale"),
                      frame_stack=meta.get("frame_stack", 1))
        cbs.append(ValidationCallback(save_path=out / "best", verbose=0, evaluations=eval_cb,
                                      policy=policy, best=_best(curve, "validation_score"),
                                      save=save, events=meta.get("validation_events")))
    if meta.get("checkpoint_freq", 0):
        cbs.append(FinalCheckpoint(save_freq=max(meta["checkpoint_freq"] // n, 1),
                                   save_path=str(out / "checkpoints"), name_prefix="rl_model",
                                   save_vecnormalize=True, save_replay_buffer=algo in OFF_POLICY))
    if progress_total is not None:
        cbs.append(TqdmCallback(progress_total, eval_cb))
    record_cb = RecordCallback(out / "training.json", record, eval_cb)
    limit = [WallClockLimit(time_limit, record)] if time_limit is not None else []
    return eval_cb, record_cb, limit + cbs + [record_cb]


def _train_env(venv, norm):
    """The training VecEnv: ``venv`` under a fresh ``VecNormalize`` unless ``normalize: false``."""
    from stable_baselines3.common.vec_env import VecNormalize
    return venv if norm is False else VecNormalize(venv, **(norm if isinstance(norm, dict) else {}))


def _stacked(venv, n: int):
    """``venv`` under SB3's ``VecFrameStack`` of ``n`` observations (config ``frame_stack``);
    ``venv`` itself for n = 1. The normalisation goes over the stack (its statistics cover the
    stacked observation), since SB3's off-policy algorithms store the observations that
    ``VecNormalize`` saw, which must have the policy's shape."""
    from stable_baselines3.common.vec_env import VecFrameStack
    return venv if n == 1 else VecFrameStack(venv, n)


def _eval_env(venv, norm):
    """The evaluation VecEnv: observations normalised with the training statistics (synced at
    every evaluation), rewards raw."""
    from stable_baselines3.common.vec_env import VecNormalize
    if norm is False:
        return venv
    kwargs = {k: v for k, v in (norm if isinstance(norm, dict) else {}).items()
              if k not in ("norm_reward", "training")}
    return VecNormalize(venv, training=False, norm_reward=False, **kwargs)


def _new_model(algo: str, meta: dict, algo_kwargs: dict, venv, seed: int, out: Path, verbose: int):
    """A fresh model; what the algorithm rejects in the hyperparameters is a ConfigError."""
    if algo == "td3" and "noise_type" in meta:
        algo_kwargs["action_noise"] = _action_noise(meta, venv.action_space.shape[0])
    try:
        model = algo_class(algo)(meta.get("policy", "MlpPolicy"), venv, seed=seed, device="cpu",
                                  tensorboard_log=str(out / "tb"), verbose=verbose, **algo_kwargs)
    except ConfigError:
        raise
    except (AssertionError, TypeError, ValueError, KeyError) as exc:
        raise ConfigError(f"{algo} hyperparameters: {exc}") from exc
    if meta.get("zero_start"):
        from ..learning.exploration import zero_action_mean
        zero_action_mean(model.policy)
    return model


def _resumed_model(algo: str, env_id: str, ckpt: tuple, norm, venv, out: Path, verbose: int):
    """The checkpoint's model on ``venv`` (under its saved VecNormalize statistics) with its
    replay buffer; a checkpoint that does not fit the algorithm or env is a ConfigError."""
    from stable_baselines3.common.vec_env import VecNormalize
    path, vn_path, rb_path = ckpt
    if norm is not False and vn_path is None:
        raise FileNotFoundError(f"checkpoint {path} has no VecNormalize statistics next to it")
    try:
        if norm is not False:
            venv = VecNormalize.load(str(vn_path), venv)
            venv.training = True
        model = algo_class(algo).load(str(path), env=venv, device="cpu",
                                       tensorboard_log=str(out / "tb"), verbose=verbose)
    except (AssertionError, TypeError, ValueError, KeyError) as exc:
        raise ConfigError(f"--resume {path} does not fit --algo {algo} --env {env_id} with these "
                          f"env_kwargs: {exc}") from exc
    if rb_path is not None and algo in OFF_POLICY:
        model.load_replay_buffer(str(rb_path))
    return model


def check_env(env_id: str, algo: str, meta: dict) -> None:
    """Build the configured environment once: a bad ``env_kwargs`` value, an action space the
    algorithm or the residual cannot drive, a residual baseline without the channels it
    commands, an ``action_log_std`` naming entries the environment lacks are ConfigErrors."""
    from gymnasium.spaces import Box

    from ..control.controllers import make_baseline
    from ..control.plant import Plant, make_env
    try:
        env = make_env(env_id, **meta["env_kwargs"])
    except (TypeError, ValueError, KeyError) as exc:
        raise ConfigError(f"env_kwargs: {exc.args[0] if exc.args else exc}") from exc
    try:
        space = env.action_space
        fix = f"{env_id} has the action space {space} here; set env_kwargs.command: continuous"
        if algo in OFF_POLICY and not isinstance(space, Box):
            raise ConfigError(f"--algo {algo} needs continuous actions: {fix}")
        residual = meta.get("residual")
        if residual is not None:
            if not isinstance(space, Box):
                raise ConfigError(f"residual: {residual} needs continuous actions: {fix}")
            try:
                make_baseline(residual, Plant.from_env(env))
            except ValueError as exc:
                raise ConfigError(f"residual: {exc}") from exc
        if "action_log_std" in meta:
            from ..learning.exploration import check_action_log_std
            if not isinstance(space, Box):
                raise ConfigError(f"action_log_std needs continuous actions: {fix}")
            check_action_log_std(meta["action_log_std"], env.unwrapped.action_names)
    finally:
        env.close()


def run_dir(checkpoint: Path) -> Path:
    """The training directory a checkpoint belongs to."""
    return checkpoint.parent.parent if checkpoint.parent.name == "checkpoints" else checkpoint.parent


def _check_resumed_run(checkpoint: Path, algo: str, env_id: str) -> None:
    """--algo and --env must be the resumed run's (its config.yaml; the algorithm also from the
    checkpoint's policy class)."""
    path = run_dir(checkpoint) / "config.yaml"
    previous = read_yaml(path) if path.is_file() else {}
    trained = dict(algo=previous.get("algo") or _checkpoint_algo(checkpoint), env_id=previous.get("env_id"))
    for flag, given, key in (("--algo", algo, "algo"), ("--env", env_id, "env_id")):
        if trained[key] not in (None, given):
            raise ConfigError(f"{flag} {given} does not match the run resumed from {checkpoint}, "
                              f"trained with {flag} {trained[key]}: pass {flag} {trained[key]}")


def _checkpoint_algo(path: Path) -> str | None:
    """The algorithm of an SB3 model zip, from its policy class (None: unknown)."""
    from ..sb3_policy import zip_algo
    try:
        return zip_algo(path)
    except ValueError as exc:
        raise ConfigError(f"--resume {exc.args[0]}") from exc


def _held_run(out: Path, continuing: bool, overwrite: bool) -> list[str]:
    """The run files in ``out`` that ``overwrite`` removes. ConfigError when ``out`` holds a run
    and neither continuing it (--resume out) nor --overwrite says what to do with it."""
    if out.exists() and not out.is_dir():
        raise ConfigError(f"--out {out} is a file, not a directory")
    held = [f for f in RUN_FILES if (out / f).exists()]
    if continuing:
        if overwrite:
            raise ConfigError(f"--overwrite would delete the run in {out} that --resume continues: "
                              f"drop --overwrite to continue its record, or --out a new directory")
        return []
    if held and not overwrite:
        raise ConfigError(f"--out {out} already holds a training run ({', '.join(held)}): continue "
                          f"it with --resume {out}, replace it with --overwrite, or choose another --out")
    return held


def _remove(out: Path, names: list[str]) -> None:
    """``--overwrite``: delete the previous run's files (nothing else in ``out``)."""
    for name in names:
        if (out / name).is_dir():
            shutil.rmtree(out / name)
        else:
            (out / name).unlink()


def _previous_record(out: Path, n_eval_episodes: int) -> tuple[list[dict], dict]:
    """The learning curve (``training.json``) and ``EvalCallback`` log (``eval/evaluations.npz``,
    as its attributes) of the run in ``out``, to be continued."""
    curve, log = [], {}
    path = out / "training.json"
    if path.is_file():
        try:
            curve = list(json.loads(path.read_text()).get("learning_curve") or [])
        except (ValueError, AttributeError) as exc:
            raise ConfigError(f"--resume {out}: {path} is not a training record ({exc}); move it "
                              f"away to resume without the previous learning curve") from exc
    npz = out / "eval" / "evaluations.npz"
    if npz.is_file():
        with np.load(npz) as d:
            log = dict(evaluations_timesteps=d["timesteps"].tolist(),
                       evaluations_results=d["results"].tolist(),
                       evaluations_length=d["ep_lengths"].tolist())
        episodes = {len(r) for r in log["evaluations_results"]}
        if episodes and episodes != {n_eval_episodes}:
            raise ConfigError(f"n_eval_episodes = {n_eval_episodes} differs from the run in {out} "
                              f"({min(episodes)} per evaluation in {npz}): keep n_eval_episodes: "
                              f"{min(episodes)} to continue it")
    return curve, log


def _best(curve: list[dict], key: str) -> float:
    """The best ``key`` of a learning curve (-inf if none): the score of the model in best/."""
    return max((float(h[key]) for h in curve if h.get(key) is not None), default=-np.inf)


def _log_episodes(monitor, path: Path, env_id: str, append: bool) -> None:
    """Attach the episode log (``monitor.csv``) to the VecMonitor once ``out`` is ready;
    a continued run appends to it."""
    from stable_baselines3.common.monitor import ResultsWriter
    monitor.results_writer = ResultsWriter(
        str(path), header={"t_start": monitor.t_start, "env_id": env_id},
        extra_keys=monitor.info_keywords, override_existing=not (append and path.is_file()))


def _written(out: Path) -> list[str]:
    """The run files in ``out`` (relative), checkpoints counted."""
    files = [f for f in ("model.zip", "vecnormalize.pkl", "config.yaml", "training.json",
                         "learning_curve.png", "best/best_model.zip", "best/vecnormalize.pkl",
                         "eval/evaluations.npz", "monitor.csv") if (out / f).is_file()]
    n = len(list((out / "checkpoints").glob("*_steps.zip")))
    return files + ([f"checkpoints/ ({n} checkpoints)"] if n else []) + \
        (["tb/"] if (out / "tb").is_dir() else [])


def set_threads(threads: int) -> None:
    """torch and numba threads. One each is several times faster for these small networks and
    the batched physics step on a few shared cores (numba's OpenMP threads oversubscribe)."""
    import numba
    import torch
    from rotordrop_env import vec_env
    n = max(1, int(threads))
    torch.set_num_threads(n)
    numba.set_num_threads(min(n, numba.config.NUMBA_NUM_THREADS))
    vec_env.TORCH_THREADS_QUIET = max(vec_env.TORCH_THREADS_QUIET, n)   # --threads N is a choice


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
