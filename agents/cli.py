"""The ``rotordrop`` command line (entry point :func:`main`) and agents' commands ``train |
evaluate | benchmark | oracle | tune | ride-through | export-policy | results | dataset | bc`` (and ``research``, :mod:`agents.research`).

This top-layer module builds the parser from every layer's ``register(subparsers)``: physics'
``drop``, ``params`` (:mod:`physics.cli`), ``study`` and ``accuracy``, then agents' own. Registration
is light: SB3, torch and the environments are imported inside the handlers, so ``rotordrop drop``
works without the rl extra and an RL command without it says so in one line.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import physics
from physics import cli as physics_cli
from physics.runs.backend import add_backend_args
from physics.cli import at_least

from . import research
from .training import imitation
from .learning.hyperparams import ALGOS

OPTIONAL_RL_MODULES = ("gymnasium", "stable_baselines3", "torch", "tensorboard", "yaml")

ERRORS = (KeyError, ValueError, FileNotFoundError)      # bad input: one line, exit 2
_SEED = at_least(0)                 # every --seed: what numpy and gymnasium accept


def _fail(command: str, exc: Exception) -> int:
    print(f"rotordrop {command}: error: {exc.args[0] if len(exc.args) == 1 else exc}", file=sys.stderr)
    return 2


def _wrote(out: str, files: list[str], wall_s: float | None = None) -> None:
    print("wrote " + ", ".join(str(Path(out) / f) for f in files)
          + (f" in {wall_s:.0f} s" if wall_s is not None else ""))


def _power_return_s(args) -> float | None:
    """--power-return-ms in seconds (the commands check it against their episode length)."""
    ms = getattr(args, "power_return_ms", None)
    return None if ms is None else 1e-3 * ms


def _env_kwargs(args) -> dict:
    from physics.scene import parse_assignment
    kw = {}
    if getattr(args, "scene", None):
        kw["scene"] = args.scene
    if getattr(args, "overrides", None):
        kw["overrides"] = {k: _number(v) for k, v in map(parse_assignment, args.overrides)}
    power_return = _power_return_s(args)
    if power_return is not None:
        kw["power_return_time"] = power_return
    return kw


def _output_args(p, default_out: str, progress: bool = True) -> None:
    """--out, --no-plots (and --quiet where there is a progress bar), shared by the commands
    that write reports."""
    p.add_argument("--out", default=default_out, help="output directory")
    p.add_argument("--no-plots", action="store_true", help="skip the PNG figures")
    if progress:
        p.add_argument("--quiet", action="store_true", help="no progress bar")


def _number(text: str):
    """'0.4' -> 0.4 (so that reports show numbers); other values stay strings for the scene."""
    try:
        return float(text)
    except ValueError:
        return text


def cmd_train(args) -> int:
    from physics.runs.backend import Backend
    from .learning.hyperparams import ConfigError
    from .training.train import command_line, train
    try:
        backend = Backend.from_args(args)
        common = dict(timesteps=args.timesteps, n_envs=args.n_envs, config=args.config,
                      verbose=args.verbose, command=command_line(), overwrite=args.overwrite,
                      eval_freq=args.eval_freq, n_eval_episodes=args.eval_episodes,
                      checkpoint_freq=args.save_freq, time_limit=args.time_limit)
        if args.seeds is None and backend.name == "local":
            print(train(args.env, args.algo, args.out, seed=args.seed, resume=args.resume,
                        threads=args.threads, progress=not args.quiet, **common).summary())
            return 0
        from .training.seeds import parse_seeds, seed_dir, train_seeds
        if args.resume is not None:
            raise ValueError("--resume continues one run on --backend local; leave out --seeds "
                             "and --backend ray")
        seeds = [args.seed] if args.seeds is None else parse_seeds(args.seeds)
        outs = [args.out] if args.seeds is None else [seed_dir(args.out, s) for s in seeds]
        results = train_seeds(seeds, args.env, args.algo, outs, backend, threads=args.threads,
                              progress=not args.quiet, **common)
    except (ConfigError, *ERRORS) as exc:
        return _fail("train", exc)
    for seed, res in zip(seeds, results):
        print(f"seed {seed}: {res.summary()}")
    return 0


def _evaluate_env_kwargs(args) -> dict:
    """evaluate's env kwargs: ``--env-kwarg`` entries, then what --scene / --set /
    --power-return-ms say (their ``overrides`` merged key by key; another key given both ways
    is an error)."""
    from .training.dataset import parse_env_kwargs
    kw = parse_env_kwargs(args.env_kwarg)
    for key, value in _env_kwargs(args).items():
        if key == "overrides":
            kw["overrides"] = {**(kw.get("overrides") or {}), **value}
        elif key in kw:
            raise ValueError(f"{key} is given twice, by --env-kwarg and by its own flag; keep one")
        else:
            kw[key] = value
    return kw


def cmd_evaluate(args) -> int:
    from .benchmarking.evaluate import evaluate, print_summary
    try:
        report = evaluate(args.policy, args.env, args.episodes, args.out,
                          env_kwargs=_evaluate_env_kwargs(args),
                          seed=args.seed, plots=not args.no_plots, compare_passive=not args.no_passive,
                          randomize=not args.fixed, video=args.video)
    except ERRORS as exc:
        return _fail("evaluate", exc)
    print_summary(report)
    return 0


def cmd_export_policy(args) -> int:
    from .learning.policies import export_policy, export_zoo
    try:
        path = (export_zoo(args.source, args.zoo, args.env) if args.zoo
                else export_policy(args.source, args.out, args.env))
    except ERRORS as exc:
        return _fail("export-policy", exc)
    print(f"wrote {path}" + (f" and its config.yml: python -m rl_zoo3.enjoy --algo "
                             f"{path.parent.name} --env {path.stem} --gym-packages rotordrop_env "
                             f"-f {args.zoo} --exp-id -1" if args.zoo else ""))
    return 0


def cmd_benchmark(args) -> int:
    from physics.runs.backend import Backend
    from .benchmarking.suites import run_suite
    try:
        run_suite(args.suite, args.out, quick=args.quick, policies=args.policy,
                  max_scenarios=args.scenarios, episodes=args.episodes, progress=not args.quiet,
                  plots=not args.no_plots, power_return=_power_return_s(args),
                  backend=Backend.from_args(args), env_id=args.env, names=args.name,
                  score=args.score, only=args.only)
    except ERRORS as exc:
        return _fail("benchmark", exc)
    return 0


def cmd_ride_through(args) -> int:
    from .benchmarking.ride_through import DELAYS, FRICTIONS, QUICK, ride_through, summary_table
    from .benchmarking.benchmark import PHASES
    grid = QUICK if args.quick else dict(frictions=FRICTIONS, delays=DELAYS, phases=PHASES)
    try:
        report = ride_through(args.out, args.env, args.policy,
                              frictions=args.friction or grid["frictions"],
                              delays=[d * 1e-3 for d in args.delay_ms] if args.delay_ms else grid["delays"],
                              phases=args.phase or grid["phases"], progress=not args.quiet,
                              plots=not args.no_plots)
    except ERRORS as exc:
        return _fail("ride-through", exc)
    print(f"ride-through time (longest power-return delay with no backward whirl and "
          f"re-levitation in every phase), {report['env_id']}:")
    print(summary_table(report))
    _wrote(args.out, report["files"], report["wall_time_s"])
    return 0


def cmd_tune(args) -> int:
    from physics.runs.backend import Backend
    from .benchmarking.tune import tune
    try:
        r = tune(args.policy, args.env, args.gain, args.out, iterations=args.iterations,
                 population=args.population, elite=args.elite, seed=args.seed,
                 progress=not args.quiet, plots=not args.no_plots, backend=Backend.from_args(args),
                 suite=args.suite)
    except ERRORS as exc:
        return _fail("tune", exc)
    print(f"{r['controller']} on {r['env_id']}: validation score {r['start_validation_score']:.2f} "
          f"(start) -> {r['validation_score']:.2f} in {r['wall_time_s']:.0f} s")
    print("gains: " + ", ".join(f"{k}={v:.4g}" for k, v in r["gains"].items()))
    _wrote(args.out, r["files"])
    return 0


def _number_list(sep: str, count: int | None):
    """argparse type: ``count`` (any if None) numbers joined by ``sep``, e.g. ``0.3:0.6``."""
    def parse(text: str) -> tuple[float, ...]:
        try:
            values = tuple(float(v) for v in text.split(sep))
        except ValueError:
            values = ()
        if not values or (count is not None and len(values) != count):
            shape = sep.join(["LO", "HI"] if count == 2 else ["E0", "E1", "..."])
            raise argparse.ArgumentTypeError(f"expected {shape} (numbers), got {text!r}")
        return values
    return parse


def cmd_oracle(args) -> int:
    from .research.oracle import oracle
    try:
        report = oracle(args.out, scenarios=args.scenarios, population=args.population,
                        iterations=args.iterations, seed=args.seed, policies=args.policy,
                        progress=not args.quiet, plots=not args.no_plots,
                        search=not args.no_search, scenario_seed=args.scenario_seed,
                        friction=args.friction, friction_bins=args.friction_bins,
                        suite=args.suite, constants=args.constant,
                        start_from_constants=args.start_from_constants,
                        interface=args.interface)
    except ERRORS as exc:
        return _fail("oracle", exc)
    _wrote(args.out, ["oracle.json", *report.get("figures", [])], report["wall_time_s"])
    return 0


def cmd_dataset(args) -> int:
    from .training.dataset import load_snippet, parse_env_kwargs, write_dataset
    try:
        r = write_dataset(args.policy, args.env, args.episodes, args.out, seed=args.seed,
                          env_kwargs=parse_env_kwargs(args.env_kwarg), dataset_id=args.name,
                          overwrite=args.overwrite, progress=not args.quiet)
    except ERRORS as exc:
        return _fail("dataset", exc)
    print(f"{r['policy']} on {r['env_id']}: {r['episodes']} episodes (seeds {r['seeds'][0]}.."
          f"{r['seeds'][-1]}), {r['steps']} steps in {r['run_s']:.1f} s "
          f"({r['episodes_per_s']:.1f} episodes/s), {r['size_mb']:.1f} MB")
    print(f"wrote the Minari data set {r['dataset_id']} at {r['path']}; load it with")
    print(f"  {load_snippet(r['dataset_id'], r['root'])}")
    return 0


def _register_train(sub) -> None:
    """``rotordrop train``."""
    p = sub.add_parser("train", help="train an SB3 agent on a rotor-drop environment")
    p.add_argument("--env", required=True, help="environment id, e.g. RotorDrop-Damping-v1")
    p.add_argument("--algo", required=True, choices=ALGOS)
    p.add_argument("--timesteps", type=int, default=None, help="override n_timesteps of the config")
    p.add_argument("--n-envs", type=int, default=None, help="override n_envs of the config")
    p.add_argument("--config", default=None,
                   metavar="FILE[:ENTRY]",
                   help="YAML with hyperparameters keyed by env id (rl-zoo3 style), applied over "
                        "the shipped agents/configs/<algo>.yaml; FILE:ENTRY picks a named entry "
                        "(e.g. agents/configs/ppo.yaml:ppo-full-scratch); a file with base: "
                        "FILE[:ENTRY] is a delta on that base")
    p.add_argument("--seed", type=_SEED, default=0)
    p.add_argument("--seeds", default=None, metavar="S1,S2,...",
                   help="train one run per seed into --out/seed_<s>, side by side (on --backend "
                        "ray one task each, holding --threads CPUs)")
    add_backend_args(p, resume=False)
    p.add_argument("--resume", default=None, metavar="DIR|CHECKPOINT.zip",
                   help="continue from a checkpoint (or the newest one in a run directory)")
    p.add_argument("--threads", type=int, default=1,
                   help="torch and numba threads (default 1: several times faster for these small "
                        "networks and the batched physics on a few shared cores)")
    p.add_argument("--out", required=True, help="output directory")
    p.add_argument("--overwrite", action="store_true",
                   help="delete the previous run's files in --out first")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.add_argument("--verbose", type=int, default=0, help="SB3 verbosity (0, 1, 2)")
    p.add_argument("--eval-freq", type=at_least(0), default=None,
                   help="environment steps between evaluations (0: none; default: the config's, "
                        "else 25000), as rl_zoo3.train's flag")
    p.add_argument("--eval-episodes", type=at_least(1), default=None,
                   help="episodes per evaluation (default: the config's, else 8)")
    p.add_argument("--save-freq", type=at_least(0), default=None,
                   help="environment steps between checkpoints (0: none; default: the config's, "
                        "else 100000)")
    p.add_argument("--time-limit", type=float, default=None, metavar="SECONDS",
                   help="wall-clock budget of the training: stop once it has passed, then "
                        "evaluate, keep best/ and save the model as at the end of a run")
    p.set_defaults(func=cmd_train)


def _register_export_policy(sub) -> None:
    """``rotordrop export-policy``."""
    p = sub.add_parser("export-policy", help="a trained policy as one zip that plain SB3 "
                                             "(PPO.load / SAC.load / TD3.load / TQC.load) runs as rotordrop does")
    p.add_argument("source", help="run directory, its best/, a model or checkpoint zip, or a "
                                  "shipped policy name")
    where = p.add_mutually_exclusive_group(required=True)
    where.add_argument("--out", help="the zip to write")
    where.add_argument("--zoo", metavar="DIR", help="write an rl-zoo3 run folder for rl_zoo3.enjoy")
    p.add_argument("--env", default=None,
                   help="the environment id a plain SB3 zip (model.save) was trained on; runs of "
                        "rotordrop train record theirs")
    p.set_defaults(func=cmd_export_policy)


def _register_evaluate(sub) -> None:
    """``rotordrop evaluate``."""
    p = sub.add_parser("evaluate", help="KPIs and plots of a policy or baseline controller")
    p.add_argument("--policy", required=True,
                   help="baseline name (passive, max-damping, whirl-switch, pid-relevitate, ...), shipped "
                        "policy name (e.g. ppo-damping), path to a training directory / model zip, "
                        "or your own controller class as package.module:Class or file.py:Class")
    p.add_argument("--env", default=None, help="environment id (default: the one the policy was "
                                               "trained on; required for controller classes and "
                                               "baselines)")
    p.add_argument("--episodes", type=int, default=10)
    p.add_argument("--seed", type=_SEED, default=0, help="episode i uses seed + i")
    p.add_argument("--scene", default=None, help="scene preset or TOML (default: the env's)")
    p.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                   help="scene override (repeatable), e.g. contact.friction=0.4")
    p.add_argument("--env-kwarg", action="append", default=[], metavar="KEY=VALUE",
                   help="gym.make kwarg over the policy's own (repeatable; Python literals), "
                        "e.g. sensor_noise=1e-6, sensor_delay=1e-4 (the sensing every controller "
                        "and policy then sees)")
    _output_args(p, "out/evaluate", progress=False)
    p.add_argument("--no-passive", action="store_true", help="skip the passive reference runs")
    p.add_argument("--fixed", action="store_true",
                   help="no scenario randomisation: every episode runs the given scene")
    p.add_argument("--power-return-ms", type=float, default=None,
                   help="re-levitation environments: power back this long after the fault [ms] "
                        "(default: the env's 50 ms, or randomised without --fixed)")
    p.add_argument("--video", action="store_true",
                   help="the first episode as episode.mp4 (episode.gif without ffmpeg)")
    p.set_defaults(func=cmd_evaluate)


def _register_dataset(sub) -> None:
    """``rotordrop dataset``."""
    p = sub.add_parser("dataset", help="seeded episodes of a controller or policy as a Minari "
                                       "data set (offline RL, behaviour cloning)")
    p.add_argument("--policy", required=True,
                   help="as in evaluate: baseline or designed controller name (whirl-brake, "
                        "inner-loop-lift, max-damping, ...), shipped policy name, training "
                        "directory / model zip, or package.module:Class / file.py:Class")
    p.add_argument("--env", default=None, help="environment id (default: the one the policy was "
                                               "trained on; required for controllers)")
    p.add_argument("--episodes", type=int, required=True, help="number of episodes (>= 1)")
    p.add_argument("--seed", type=_SEED, default=0, help="episode i is reset with seed + i")
    p.add_argument("--env-kwarg", action="append", default=[], metavar="KEY=VALUE",
                   help="gym.make kwarg over the policy's own (repeatable; Python literals), "
                        "e.g. episode_time=0.1, randomize=False, "
                        "overrides=\"{'contact.friction': 0.4}\"")
    p.add_argument("--out", required=True,
                   help="Minari datasets root: the data set goes to OUT/<name> "
                        "(MINARI_DATASETS_PATH=OUT to load it)")
    p.add_argument("--name", default=None,
                   help="Minari dataset id (default rotordrop/<task>/<policy>-v0)")
    p.add_argument("--overwrite", action="store_true", help="replace a data set of that id")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=cmd_dataset)


def _register_benchmark(sub) -> None:
    """``rotordrop benchmark``."""
    p = sub.add_parser("benchmark", help="every baseline and shipped policy on a fixed scenario suite")
    p.add_argument("--quick", action="store_true",
                   help="a reduced suite: 5 scenarios x 2 phases, every task: about 35 CPU-s "
                        "(140 s wall on a loaded 2-core machine); with --policy only the tasks of "
                        "the given policies and their references (ppo-damping: 10 CPU-s); with "
                        "--suite robust its first 40 drops")
    p.add_argument("--suite", default="nominal",
                   help="nominal (default: the fixed scenario suite) or robust (200 drawn drops "
                        "under sensor noise, latency, actuator spread and plant variation, Full "
                        "task; docs/agents.md 'Robust suite'), or robust-legacy (the robust "
                        "suite's earlier test drops, seeds 30000-30199, to reproduce old numbers)")
    p.add_argument("--score", default="severity",
                   help="severity (default: the whirl verdict plus its severity, the peak "
                        "backward revolutions against the passive drop's) or legacy (the whirl "
                        "verdict alone); docs/agents.md 'Score'")
    p.add_argument("--policy", action="append", default=None,
                   help="extra policies or controllers to include (repeatable): a training "
                        "directory or model .zip (shown as name@run), or your own controller "
                        "class as package.module:Class or file.py:Class (see docs/agents.md)")
    p.add_argument("--env", default=None,
                   help="the environment id a --policy model was trained on when nothing records "
                        "it (a plain SB3 zip from model.save)")
    p.add_argument("--name", action="append", default=None,
                   help="the leaderboard name of a --policy model given by path (repeatable: one "
                        "per model, in order; default name@run)")
    p.add_argument("--only", action="append", default=None, metavar="ROW",
                   help="a drawn suite (--suite robust) with only these baselines or shipped "
                        "policies (repeatable), beside the --policy extras and the passive "
                        "reference: a subset of the leaderboard, same drops and bootstrap")
    p.add_argument("--power-return-ms", type=float, default=None,
                   help="power-return delay of the re-levitation tasks [ms] (default: the "
                        "environments' 50 ms; the 'power back at 0.15 s' scenario keeps its own)")
    add_backend_args(p, resume=False)
    _output_args(p, "out/benchmark")
    p.add_argument("--scenarios", type=int, default=None, help=argparse.SUPPRESS)
    p.add_argument("--episodes", type=int, default=None, help=argparse.SUPPRESS)
    p.set_defaults(func=cmd_benchmark)


def _register_oracle(sub) -> None:
    """``rotordrop oracle``."""
    p = sub.add_parser("oracle", help="per-scenario searched open-loop command sequences of the "
                                      "supervisor interface: a score reachable on each drop (a "
                                      "lower bound, not a ceiling)")
    p.add_argument("--scenarios", type=at_least(1), default=20, help="drawn scenarios (default 20)")
    p.add_argument("--population", type=at_least(2), default=24,
                   help="command sequences per generation (one batched rollout)")
    p.add_argument("--iterations", type=at_least(0), default=10, help="generations (default 10)")
    p.add_argument("--seed", type=_SEED, default=0, help="search seed")
    p.add_argument("--suite", default="full",
                   help="full (default: drops drawn from friction 0.38-0.6, power back 30-70 ms) "
                        "or robust (the first --scenarios drops of `rotordrop benchmark --suite "
                        "robust`: sensor noise, latency, actuator spread, plant variation)")
    p.add_argument("--scenario-seed", type=_SEED, default=None,
                   help="seed of the first drawn scenario (default 10000, with --suite robust "
                        "the suite's 50000; scenario i uses it + i)")
    p.add_argument("--no-search", action="store_true",
                   help="score the rows only (no oracle search), e.g. on 200 scenarios")
    p.add_argument("--friction", type=_number_list(":", 2), default=None, metavar="LO:HI",
                   help="friction range the scenarios are drawn from (default 0.38:0.6; "
                        "0 <= LO < HI <= 1)")
    p.add_argument("--friction-bins", type=_number_list(",", None), default=None,
                   metavar="E0,E1,...", help="edges of the whirl-rate-per-friction table, from "
                   "LO to HI (default: 0.38,0.44,0.5,0.55,0.6 on the default range, else "
                   "0.05-wide bins)")
    p.add_argument("--policy", action="append", default=None,
                   help="extra rows: a training directory / model .zip or module:Class "
                        "(repeatable)")
    p.add_argument("--constant", type=_number_list(":", 2), action="append", default=None,
                   metavar="GAIN:OFFSET_R",
                   help="extra designed row (repeatable): the inner-loop commands with a constant "
                        "PID gain scale and radial reference offset on both planes (supervisor "
                        "actions in [-1, 1]), named 'constant g=GAIN r=OFFSET_R': the law of "
                        "inner-loop-lift (0.5:-0.5) at its 5 ms control step")
    p.add_argument("--start-from-constants", action="store_true",
                   help="start each scenario's search from the best of inner-loop and the "
                        "--constant rows there (default: from inner-loop)")
    p.add_argument("--interface", default="supervisor",
                   help="what the search commands: supervisor (default: the supervisor "
                        "interface's segments) or currents (open-loop corrections of "
                        "whirl-brake's coil currents after the power return, 1 ms steps)")
    _output_args(p, "out/oracle")
    p.set_defaults(func=cmd_oracle)


def _register_tune(sub) -> None:
    """``rotordrop tune``."""
    p = sub.add_parser("tune", help="tune a controller's gains for the benchmark score on the "
                                    "validation suite (scenarios the benchmark does not use)")
    p.add_argument("--policy", required=True,
                   help="controller class: a baseline name, package.module:Class or file.py:Class; "
                        "its constructor takes the gains as keyword arguments")
    p.add_argument("--env", required=True, help="RotorDrop-Damping-v1, RotorDrop-Relevitate-v1 "
                                                "or RotorDrop-Full-v1")
    p.add_argument("--gain", action="append", default=[], metavar="NAME=LO:HI",
                   help="a gain and its search range (repeatable), e.g. --gain kp=0:30")
    p.add_argument("--iterations", type=int, default=12, help="generations (default 12)")
    p.add_argument("--population", type=int, default=24, help="candidates per generation")
    p.add_argument("--elite", type=int, default=6, help="best candidates the next generation is fitted to")
    p.add_argument("--seed", type=_SEED, default=0)
    p.add_argument("--suite", default="nominal",
                   help="validation set: nominal (default) or robust (the robust suite's "
                        "distribution, Full task: see docs/agents.md 'Robust suite')")
    add_backend_args(p, resume=False)
    _output_args(p, "out/tune")
    p.set_defaults(func=cmd_tune)


def _register_ride_through(sub) -> None:
    """``rotordrop ride-through``."""
    p = sub.add_parser("ride-through", help="how late the AMB power may return for a controller "
                                            "to stop the whirl: friction x power-return map")
    p.add_argument("--env", default="RotorDrop-Relevitate-v1",
                   help="RotorDrop-Relevitate-v1 (damper at the scene's C_s) or RotorDrop-Full-v1")
    p.add_argument("--policy", action="append", default=None,
                   help="a re-levitating controller (one that sets the levitate or currents "
                        "channel): baseline or shipped policy name, a path, or a controller class "
                        "module:Class / file.py:Class (repeatable; default: every re-levitating "
                        "baseline and the shipped policies of --env)")
    p.add_argument("--friction", type=float, action="append", default=None,
                   help="friction coefficient (repeatable; default 0.30, 0.35, ..., 0.60)")
    p.add_argument("--delay-ms", type=float, action="append", default=None,
                   help="power-return delay after the fault [ms] (repeatable; default 0, 10, ..., 100)")
    p.add_argument("--phase", type=float, action="append", default=None,
                   help="unbalance phase [deg] (repeatable; default the benchmark's 0, 90, 180, 270)")
    p.add_argument("--quick", action="store_true", help="3 frictions x 3 delays x 2 phases")
    _output_args(p, "out/ride_through")
    p.set_defaults(func=cmd_ride_through)


#: agents' commands, each registering its own parser (``imitation`` registers ``bc``)
COMMANDS = (_register_train, _register_export_policy, _register_evaluate, _register_dataset,
            imitation.register, _register_benchmark, _register_oracle, _register_tune,
            _register_ride_through)


def register(sub) -> None:
    """Agents' commands (:data:`COMMANDS`), in the order of ``rotordrop --help``."""
    for register_command in COMMANDS:
        register_command(sub)


def cmd_results(args) -> int:
    from .benchmarking import results
    return results.run(args)


def register_results(sub) -> None:
    from .benchmarking import results
    p = sub.add_parser("results", help="docs/results.md and the README leaderboard from the "
                                       "benchmark output committed in docs/data")
    results.add_arguments(p)
    p.set_defaults(func=cmd_results)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="rotordrop", description="AMB rotor drop onto retainer "
                                     "bearings: simulation, studies, Gymnasium environments and agents")
    parser.add_argument("--version", action="version", version=f"rotordrop {physics.__version__}")
    sub = parser.add_subparsers(dest="command", required=True)
    for register_commands in (physics_cli.register, register,
                              register_results, research.register):
        register_commands(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    try:
        return physics_cli.run(args)
    except ModuleNotFoundError as exc:      # an RL command without the rl extra
        if exc.name and exc.name.split(".")[0] == "minari":
            print(f"rotordrop: error: `rotordrop {args.command}` needs minari, the offline extra: "
                  "python3 -m pip install -c constraints.txt -e \".[rl,offline]\"", file=sys.stderr)
            return 2
        if exc.name and exc.name.split(".")[0] in OPTIONAL_RL_MODULES:
            print(f"rotordrop: error: `rotordrop {args.command}` needs {exc.name.split('.')[0]}, "
                  "part of the rl extra: python3 -m pip install -c constraints.txt -e \".[rl]\"",
                  file=sys.stderr)
            return 2
        raise


if __name__ == "__main__":
    sys.exit(main())
