"""Hyperparameters: rl-zoo3-style YAML files keyed by environment id.

``agents/configs/<algo>.yaml`` holds the shipped defaults (a block per env id) and one entry per
shipped policy that shares an env id with another (keyed by the policy's name; its
``agents/policies/<name>.json`` names the env id). ``--config`` is ``FILE`` or ``FILE:ENTRY``: the
block of an rl-zoo3-style file (for the env id, or the named entry; a flat mapping is the block
for the env id) over the shipped default block, or a delta, a block with ``base: FILE[:ENTRY]``
and the keys that differ, over its resolved base (:func:`load_hyperparams`; the experiment
variants in ``docs/experiments/configs/`` are deltas). Besides the algorithm's constructor
arguments a block may hold:

=================  ===========================================================================
``n_timesteps``    training steps (``--timesteps`` overrides)
``n_envs``         parallel environments in the batched VecEnv (``--n-envs`` overrides)
``policy``         SB3 policy name (``MlpPolicy``)
``policy_kwargs``  a Python dict literal as a string, e.g. ``"dict(net_arch=[64, 64])"``
``normalize``      ``true``/``false`` or a dict literal of ``VecNormalize`` arguments
``env_kwargs``     keyword arguments of ``gym.make`` (``randomize``, ``overrides``...)
``eval_freq``      environment steps between evaluations (``EvalCallback``)
``n_eval_episodes`` episodes per evaluation
``checkpoint_freq`` environment steps between checkpoints
``noise_type``     TD3 action noise (``normal`` | ``ornstein-uhlenbeck``), with ``noise_std``
``reward``         ``env`` (the environment's reward, default) or ``kpi`` (the KPI-aligned
                   reward of :mod:`agents.learning.reward`), with optional ``reward_kwargs``
``residual``       a baseline controller name: the agent's action corrects that controller's
                   (:mod:`agents.control.residual`; the saved policy applies it too); or
                   ``{law: NAME, tuned_on: SUITE}``: that law with the constants tuned on the
                   suite's validation drops (``rotordrop research tune-designed``), written
                   into the run as ``{law: NAME, gains: {...}}`` (also accepted as such)
``residual_scale`` the residual's authority: env action = clip(base + scale * a, -1, 1)
                   (default 2: the agent can override the baseline anywhere)
``validation``     ``true``: keep as ``best/`` the model with the highest benchmark score on the
                   validation suite (:class:`agents.benchmarking.benchmark.Validator`: frictions and unbalance
                   phases the benchmark does not use) instead of the highest evaluation reward
``validation_events`` with ``validation`` on ``RotorDrop-Recover-v1``: how many of the recover
                   suite's validation events score a model (default 30 of its 60;
                   :class:`agents.benchmarking.recover.RecoverValidator`: recovered %, ties
                   broken by the mean peak contact force)
``action_log_std`` PPO: initial log std of named action entries, e.g. ``{gain: -1.0}``; the
                   others keep ``log_std_init`` (:mod:`agents.learning.exploration`)
``zero_start``     ``true``: the policy's action mean starts at exactly zero (its last layer
                   zeroed, :func:`agents.learning.exploration.zero_action_mean`), so the
                   deterministic initial policy is a = 0: with ``residual``, the baseline itself
                   (SAC's, TQC's and TD3's default initialisation start it further away)
``frame_stack``    memory: the policy sees the last N (normalised) observations, newest last, as
                   rl-zoo3's ``frame_stack`` (``VecFrameStack``); the saved policy stacks them
                   itself (:class:`agents.sb3_policy.FrameStack`; default 1)
=================  ===========================================================================

The same file trains with rl-zoo3 (``python -m rl_zoo3.train --algo ppo --env ID --gym-packages
rotordrop_env -conf agents/configs/ppo.yaml``): there, the project's options are entries rl-zoo3
understands, and ``rotordrop train`` reads them as the keys above (:func:`project_keys`):

=====================================================================  ===========================
rl-zoo3 entry                                                          means
=====================================================================  ===========================
``vec_env_wrapper: [{agents.control.residual.ResidualAction: {base: B, scale: S}}]``  ``residual: B``,
                                                                       ``residual_scale: S``
``vec_env_wrapper: [{agents.learning.reward.KpiReward: {weights...}}]``         ``reward: kpi``,
                                                                       ``reward_kwargs``
``callback: [agents.training.validation.ValidationCallback]``                   ``validation: true``
``callback: [{agents.training.validation.ValidationCallback: {events: N}}]``      ``validation_events: N``
``callback: [{agents.learning.exploration.ActionSpread: {log_std: {...}}}]``    ``action_log_std: {...}``
=====================================================================  ===========================

(residual first: the list is applied inside out). ``eval_freq``, ``n_eval_episodes`` and
``checkpoint_freq`` are ``rotordrop train``'s ``--eval-freq``, ``--eval-episodes`` and
``--save-freq`` (rl-zoo3's flags of the same names), default :data:`RUN_DEFAULTS`; the keys
still work in a config for ``rotordrop train`` alone.

``learning_rate``, ``clip_range`` accept ``lin_<value>`` (linear decay to zero, as in rl-zoo3);
``train_freq`` a list ``[1, "episode"]`` (made the tuple SB3 wants, as in rl-zoo3).
Any other key must be a constructor argument of the algorithm (:func:`check_sb3` checks the
keys against the signatures of the algorithm, ``VecNormalize`` and the environment before
training starts).
"""
from __future__ import annotations

import ast
import copy
import functools
import inspect
import re
from importlib import resources
from pathlib import Path
from typing import Any

from .config_checks import ConfigError, check_keys, is_finite_number

#: the algorithms ``rotordrop train`` runs: name -> (module, class); one line per algorithm, and
#: a shipped ``agents/configs/<name>.yaml`` with a block per env id
ALGO_CLASSES = {"ppo": ("stable_baselines3", "PPO"), "sac": ("stable_baselines3", "SAC"),
                "td3": ("stable_baselines3", "TD3"), "tqc": ("sb3_contrib", "TQC"),
                "crossq": ("sb3_contrib", "CrossQ")}
ALGOS = tuple(ALGO_CLASSES)
#: algorithms from sb3-contrib (the ``rl`` extra installs it)
CONTRIB_ALGOS = tuple(a for a, (module, _) in ALGO_CLASSES.items() if module == "sb3_contrib")
META_KEYS = ("n_timesteps", "n_envs", "policy", "policy_kwargs", "normalize", "env_kwargs",
             "eval_freq", "n_eval_episodes", "checkpoint_freq", "noise_type", "noise_std",
             "reward", "reward_kwargs", "residual", "residual_scale", "validation",
             "validation_events", "action_log_std", "frame_stack", "zero_start")
REWARDS = ("env", "kpi")
#: evaluation and checkpoint intervals [environment steps] and evaluation episodes of a run
#: when neither the command line nor the config sets them (rl-zoo3's eval_freq too)
RUN_DEFAULTS = dict(eval_freq=25_000, n_eval_episodes=8, checkpoint_freq=100_000)
#: rl-zoo3 entries (class path -> the project keys they set)
RESIDUAL_WRAPPER = "agents.control.residual.ResidualAction"
KPI_WRAPPER = "agents.learning.reward.KpiReward"
VALIDATION_CALLBACK = "agents.training.validation.ValidationCallback"
SPREAD_CALLBACK = "agents.learning.exploration.ActionSpread"
#: project keys that rl-zoo3's ``callback:`` entries set
CALLBACK_KEYS = ("validation", "validation_events", "action_log_std")
WRAPPER_KEYS = ("residual", "residual_scale", "reward", "reward_kwargs")
#: rl-zoo3 keys rotordrop train cannot honour (the batched VecEnv steps unwrapped envs)
ZOO_ONLY = {"env_wrapper": "gym wrappers around each environment",
            "monitor_kwargs": "Monitor arguments"}
SCHEDULE_KEYS = ("learning_rate", "clip_range")
#: constructor arguments ``rotordrop train`` sets itself, and where they come from instead
SET_BY_TRAIN = {"policy": "the config key policy", "env": "--env", "seed": "--seed",
                "device": "always cpu", "tensorboard_log": "--out", "verbose": "--verbose",
                "action_noise": "noise_type / noise_std", "_init_setup_model": "internal"}
#: integer hyperparameters and their smallest allowed value
INTEGERS = {"n_timesteps": 1, "n_envs": 1, "eval_freq": 0, "n_eval_episodes": 1, "checkpoint_freq": 0,
            "n_steps": 1, "batch_size": 1, "n_epochs": 1, "buffer_size": 1, "learning_starts": 0}
#: hyperparameters that are fractions in [0, 1]
FRACTIONS = ("gamma", "gae_lambda", "tau")
#: SB3 arguments that take a tuple, which YAML writes as a list (``train_freq: [1, episode]``)
TUPLES = ("train_freq",)


def residual_spec(value):
    """The ``residual`` key checked: a baseline's name, ``{law, gains}``, or ``{law, tuned_on}``
    (a suite whose tuned record gives the gains: ``rotordrop train`` writes them in,
    :func:`agents.training.train.resolve_config`); ConfigError otherwise."""
    from ..control.controllers import BASELINES, baseline_name
    if isinstance(value, dict) and set(value) == {"law", "tuned_on"}:
        if not isinstance(value["tuned_on"], str):
            raise ConfigError(f"residual.tuned_on must be a suite's name, got {value['tuned_on']!r}")
        if value["law"] not in BASELINES:
            raise ConfigError(f"residual.law must be a baseline controller ({', '.join(BASELINES)}), "
                              f"got {value['law']!r}")
        return value
    try:
        baseline_name(value)
    except ValueError as exc:
        raise ConfigError(f"residual must be a baseline controller ({', '.join(BASELINES)}) or "
                          f"{{law: NAME, tuned_on: SUITE}} or {{law: NAME, gains: {{...}}}}: "
                          f"{exc}") from exc
    return value


def _yaml():
    try:
        import yaml
    except ImportError as exc:   # pragma: no cover - the rl extra installs it
        raise ConfigError("reading hyperparameter files needs PyYAML: pip install 'rotordrop[rl]'") from exc
    return yaml


@functools.cache
def _loader():
    """PyYAML's safe loader, reading ``1e-3`` and ``3e5`` as floats as YAML 1.2 does (YAML 1.1
    wants a dot and a signed exponent, so ``learning_rate: 1e-3`` would arrive as a string)."""
    yaml = _yaml()

    class Loader(yaml.SafeLoader):
        pass

    Loader.add_implicit_resolver("tag:yaml.org,2002:float",
                                 re.compile(r"^[-+]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)[eE][-+]?[0-9]+$"),
                                 list("-+0123456789."))
    return Loader


def load_yaml(text: str):
    """Parse YAML text with :func:`_loader` (configs and a run's config.yaml)."""
    return _yaml().load(text, Loader=_loader())


def algo_class(algo: str):
    """The Stable-Baselines3 (or sb3-contrib: TQC, CrossQ) class of ``algo``
    (:data:`ALGO_CLASSES`)."""
    import importlib
    module, name = ALGO_CLASSES[algo]
    try:
        return getattr(importlib.import_module(module), name)
    except ImportError as exc:   # pragma: no cover - the rl extra installs sb3-contrib
        raise ConfigError(f"--algo {algo} needs sb3-contrib: pip install 'rotordrop[rl]'") from exc


def shipped_dir() -> Path:
    """The directory of the shipped hyperparameter files (``agents/configs``)."""
    return Path(str(resources.files("agents") / "configs"))


def default_config_path(algo: str) -> Path:
    if algo not in ALGOS:
        raise ConfigError(f"algo must be one of {', '.join(ALGOS)}, got {algo!r}")
    return shipped_dir() / f"{algo}.yaml"


def read_yaml(path: str | Path) -> dict:
    path = Path(path)
    if not path.is_file():
        raise ConfigError(f"config file {path} does not exist")
    try:
        data = load_yaml(path.read_text())
    except Exception as exc:
        raise ConfigError(f"config file {path} is not valid YAML: {exc}") from exc
    if not isinstance(data, dict):
        raise ConfigError(f"config file {path} must be a mapping (env id -> hyperparameters)")
    return data


def split_ref(ref: str | Path) -> tuple[str, str | None]:
    """``"FILE:ENTRY"`` -> (FILE, ENTRY); ``"FILE"`` -> (FILE, None)."""
    text = str(ref)
    head, sep, tail = text.rpartition(":")
    if sep and tail and "/" not in tail and head.endswith((".yaml", ".yml")):
        return head, tail
    return text, None


def _locate(name: str, near: Path | None) -> Path:
    """A config file: relative to ``near`` (the file naming it as its base) or, without ``near``,
    to the current directory; then the shipped file of that name (``ppo.yaml``,
    ``agents/configs/ppo.yaml`` from any directory)."""
    path = Path(name)
    if path.is_absolute():
        return path
    here = (near / path) if near is not None else path
    if here.is_file():
        return here
    shipped = shipped_dir() / path.name
    if shipped.is_file() and path.parent in (Path("."), Path("agents/configs")):
        return shipped
    return here


def _layer(hp: dict, block: dict) -> dict:
    """``block`` (read with :func:`project_keys`) over ``hp``: ``env_kwargs`` merged key by key, a
    ``vec_env_wrapper`` / ``callback`` entry replacing what ``hp``'s entries set, others replaced."""
    hp = copy.deepcopy(hp)
    for entry, keys in (("vec_env_wrapper", WRAPPER_KEYS), ("callback", CALLBACK_KEYS)):
        if entry in block:
            for key in keys:
                hp.pop(key, None)
    for key, value in project_keys(block).items():
        if key == "env_kwargs" and isinstance(value, dict):
            hp.setdefault("env_kwargs", {}).update(copy.deepcopy(value))
        else:
            hp[key] = copy.deepcopy(value)
    return hp


def _entry_env(path: Path, entry: str) -> str | None:
    """The env id an entry trains: the entry itself if it is an env id, else the ``env_id`` of the
    shipped policy of that name (``agents/policies/<entry>.json``) when it is a shipped file."""
    if entry.startswith("RotorDrop-"):
        return entry
    if path.parent.resolve() == shipped_dir().resolve():
        meta = Path(str(resources.files("agents") / "policies" / f"{entry}.json"))
        if meta.is_file():
            import json
            return json.loads(meta.read_text()).get("env_id")
    return None


def _resolve(algo: str, env_id: str, ref: str, near: Path | None, chain: tuple[str, ...]) -> dict:
    """The hyperparameters ``ref`` (``FILE`` or ``FILE:ENTRY``) stands for (module docstring)."""
    name, entry = split_ref(ref)
    path = _locate(name, near)
    data = read_yaml(path)
    key = f"{path.resolve()}:{entry or ''}"
    shown = f"{name}:{entry}" if entry else name
    if key in chain:
        raise ConfigError(f"config {shown}: its base chain comes back to itself "
                          f"({' -> '.join([c.rsplit('/', 1)[-1].rstrip(':') for c in chain] + [shown])})")
    chain = chain + (key,)
    shipped = path.resolve().parent == shipped_dir().resolve() and path.stem in ALGOS
    if shipped and path.stem != algo:
        raise ConfigError(f"config {shown} holds {path.stem} hyperparameters: train it with "
                          f"--algo {path.stem}, not --algo {algo}")
    if "base" in data:                                        # a delta file: one flat block
        if entry is not None:
            raise ConfigError(f"config {name} is a delta on base {data['base']!r} (one block, no "
                              f"entries): name it without :{entry}")
        block = data
    else:
        want = entry or env_id
        if want in data:
            block = data[want]
        elif entry is None and not any(k.startswith("RotorDrop-") for k in data) and not shipped:
            block = data                                      # a flat mapping for --env
        else:
            raise ConfigError(f"config file {path} has no block for {want} (has {', '.join(map(str, data))})")
        if not isinstance(block, dict):
            raise ConfigError(f"config file {path}: the {want} block must be a mapping")
        if entry is not None:
            pinned = _entry_env(path, entry)
            if pinned is not None and pinned != env_id:
                raise ConfigError(f"config {shown} trains {pinned}; pass --env {pinned}, "
                                  f"not --env {env_id}")
    if "base" in block:
        base = block["base"]
        if not isinstance(base, str) or not base:
            raise ConfigError(f"config {shown}: base must name a file (FILE or FILE:ENTRY), got {base!r}")
        hp = _resolve(algo, env_id, base, path.parent, chain)
        return _layer(hp, {k: v for k, v in block.items() if k != "base"})
    if shipped and entry in (None, env_id):
        return project_keys(copy.deepcopy(block))             # a shipped default: the bottom
    return _layer(_resolve(algo, env_id, str(default_config_path(algo)), None, chain), block)


def load_hyperparams(algo: str, env_id: str, config: str | Path | None = None) -> dict:
    """The hyperparameters for (algo, env id). Without ``config``: the shipped default block
    (``agents/configs/<algo>.yaml``, key ``env_id``). ``config`` is ``FILE`` or ``FILE:ENTRY``:

    * an rl-zoo3 file: its block for ``env_id`` (or ``ENTRY``; a flat mapping is the block for
      ``env_id``) read over the shipped default block;
    * a block (or a whole file) with a ``base:`` key (``FILE`` or ``FILE:ENTRY``, a path relative
      to the file that names it, or a shipped file's name such as ``ppo.yaml``): that base,
      resolved the same way, with the block's keys on top (a delta).

    ``env_kwargs`` merge key by key, a ``vec_env_wrapper`` / ``callback`` entry replaces what the
    entries below it set, any other key replaces its value. A base chain that comes back to a
    file it has read, an algorithm or env id other than the one trained, or a missing file or
    entry are ConfigErrors."""
    if algo not in ALGOS:
        raise ConfigError(f"algo must be one of {', '.join(ALGOS)}, got {algo!r}")
    ref = str(default_config_path(algo)) if config is None else str(config)
    return _resolve(algo, env_id, ref, None, ())


def project_keys(block: dict) -> dict:
    """A config block with its rl-zoo3 entries (``vec_env_wrapper``, ``callback``; module
    docstring) turned into the project's keys. ConfigError for an entry ``rotordrop train``
    cannot run, and for an option given both ways."""
    out = {k: v for k, v in block.items() if k not in ("vec_env_wrapper", "callback")}
    for key, what in ZOO_ONLY.items():
        if key in out:
            raise ConfigError(f"{key} ({what}) is an rl-zoo3 option that rotordrop train cannot "
                              f"apply (its batched VecEnv steps the environments unwrapped): "
                              f"train with python -m rl_zoo3.train, or remove it")
    found = {}
    for name, kwargs in _entries(block.get("vec_env_wrapper"), "vec_env_wrapper"):
        if name == RESIDUAL_WRAPPER:
            check_keys(name, kwargs, ("base", "scale"))
            if "base" not in kwargs:
                raise ConfigError(f"vec_env_wrapper {name} needs base: <baseline controller>")
            found["residual"] = kwargs["base"]
            if "scale" in kwargs:
                found["residual_scale"] = kwargs["scale"]
        elif name == KPI_WRAPPER:
            found["reward"] = "kpi"
            if kwargs:
                found["reward_kwargs"] = dict(kwargs)
        else:
            raise ConfigError(f"vec_env_wrapper {name}: rotordrop train knows {RESIDUAL_WRAPPER} "
                              f"and {KPI_WRAPPER}; other wrappers run under python -m rl_zoo3.train")
    for name, kwargs in _entries(block.get("callback"), "callback"):
        if name == SPREAD_CALLBACK:
            check_keys(name, kwargs, ("log_std", "verbose"))
            found["action_log_std"] = kwargs.get("log_std")
            continue
        if name != VALIDATION_CALLBACK:
            raise ConfigError(f"callback {name}: rotordrop train knows {VALIDATION_CALLBACK} "
                              f"(validation: true) and {SPREAD_CALLBACK} (action_log_std); other "
                              "callbacks run under python -m rl_zoo3.train")
        check_keys(name, kwargs, ("eval_freq", "save_path", "verbose", "events"))
        if kwargs.get("save_path") is not None:
            raise ConfigError(f"callback {name}: save_path is where rl-zoo3 keeps the best model; "
                              "rotordrop train keeps it in --out/best/: remove save_path (or pass "
                              "it with rl_zoo3.train's -params)")
        found["validation"] = True
        if "events" in kwargs:
            found["validation_events"] = kwargs["events"]
        if "eval_freq" in kwargs:
            found["eval_freq"] = kwargs["eval_freq"]
    for key, value in found.items():
        if key in out and out[key] != value:
            raise ConfigError(f"{key} is given twice, as {key}: {out[key]!r} and by an rl-zoo3 "
                              f"entry ({value!r}); keep one")
        out[key] = value
    return out


def _entries(value: Any, key: str) -> list[tuple[str, dict]]:
    """rl-zoo3's ``NAME`` / ``{NAME: kwargs}`` / a list of those -> [(NAME, kwargs)]."""
    if value is None:
        return []
    items = value if isinstance(value, list) else [value]
    out = []
    for item in items:
        if isinstance(item, str):
            out.append((item, {}))
        elif isinstance(item, dict) and len(item) == 1:
            name, kwargs = next(iter(item.items()))
            if kwargs is not None and not isinstance(kwargs, dict):
                raise ConfigError(f"{key} {name}: its arguments must be a mapping, got {kwargs!r}")
            out.append((str(name), dict(kwargs or {})))
        else:
            raise ConfigError(f"{key}: each entry is a class path or {{class path: {{arguments}}}}, "
                              f"got {item!r}")
    return out


def parse_literal(text: Any, key: str) -> Any:
    """Evaluate a restricted Python literal: constants, lists, tuples, dicts, ``dict(...)``,
    and ``nn.<Module>`` names (torch activation functions), as rl-zoo3 configs write them."""
    if not isinstance(text, str):
        return text
    try:
        tree = ast.parse(text, mode="eval").body
    except SyntaxError as exc:
        raise ConfigError(f"{key}: cannot parse {text!r}: {exc.msg}") from exc

    def ev(node):
        if isinstance(node, ast.Constant):
            return node.value
        if isinstance(node, (ast.List, ast.Tuple)):
            items = [ev(e) for e in node.elts]
            return items if isinstance(node, ast.List) else tuple(items)
        if isinstance(node, ast.Dict):
            return {ev(k): ev(v) for k, v in zip(node.keys, node.values)}
        if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub):
            return -ev(node.operand)
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id == "dict" \
                and not node.args:
            return {kw.arg: ev(kw.value) for kw in node.keywords}
        if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) and node.value.id == "nn":
            import torch.nn as nn
            if not hasattr(nn, node.attr):
                raise ConfigError(f"{key}: torch.nn has no {node.attr}")
            return getattr(nn, node.attr)
        raise ConfigError(f"{key}: only literals, dict(...) and nn.<Name> are allowed, got "
                          f"{ast.unparse(node)!r}")

    return ev(tree)


def schedule(value: Any, key: str):
    """A float, or ``lin_<v>``: a linear schedule from v to 0 over training."""
    if isinstance(value, str) and value.startswith("lin_"):
        try:
            start = float(value[4:])
        except ValueError as exc:
            raise ConfigError(f"{key}: bad linear schedule {value!r} (write lin_3e-4)") from exc
        return lambda progress_remaining: progress_remaining * start
    try:
        return float(value)
    except (TypeError, ValueError) as exc:
        raise ConfigError(f"{key}: expected a number or lin_<value>, got {value!r}") from exc


def split(hp: dict) -> tuple[dict, dict]:
    """(meta settings, algorithm constructor kwargs) with literals and schedules resolved."""
    meta = {k: hp[k] for k in META_KEYS if k in hp}
    algo_kwargs = {k: v for k, v in hp.items() if k not in META_KEYS}
    for k in SCHEDULE_KEYS:
        if k in algo_kwargs:
            algo_kwargs[k] = schedule(algo_kwargs[k], k)
    for k in TUPLES:
        if isinstance(algo_kwargs.get(k), list):              # as rl-zoo3 converts it
            algo_kwargs[k] = tuple(algo_kwargs[k])
    if "policy_kwargs" in meta:
        pk = parse_literal(meta["policy_kwargs"], "policy_kwargs")
        if not isinstance(pk, dict):
            raise ConfigError(f"policy_kwargs must be a dict, got {pk!r}")
        algo_kwargs["policy_kwargs"] = pk
    norm = parse_literal(meta.get("normalize", False), "normalize")
    if not isinstance(norm, (bool, dict)):
        raise ConfigError(f"normalize must be true/false or a dict, got {norm!r}")
    meta["normalize"] = norm
    stack = meta.setdefault("frame_stack", 1)
    if isinstance(stack, bool) or not isinstance(stack, int) or not 1 <= stack <= 64:
        raise ConfigError(f"frame_stack must be an integer in [1, 64] (observations the policy "
                          f"sees at once, newest last), got {stack!r}")
    meta.setdefault("reward", "env")
    if meta["reward"] not in REWARDS:
        raise ConfigError(f"reward must be one of {', '.join(REWARDS)}, got {meta['reward']!r}")
    if meta.get("residual") is not None:
        meta["residual"] = residual_spec(meta["residual"])
    if meta.get("residual") is not None:
        from ..control.residual import RESIDUAL_SCALE
        meta.setdefault("residual_scale", RESIDUAL_SCALE)
    if "residual_scale" in meta:
        try:
            meta["residual_scale"] = float(meta["residual_scale"])
        except (TypeError, ValueError) as exc:
            raise ConfigError(f"residual_scale must be a number, got {meta['residual_scale']!r}") from exc
        if not 0.0 < meta["residual_scale"] <= 2.0:
            raise ConfigError(f"residual_scale must be in (0, 2], got {meta['residual_scale']}")
    for flag in ("validation", "zero_start"):
        if not isinstance(meta.setdefault(flag, False), bool):
            raise ConfigError(f"{flag} must be true or false, got {meta[flag]!r}")
    if "validation_events" in meta:
        n = meta["validation_events"]
        if not meta["validation"]:
            raise ConfigError(f"validation_events: {n!r} needs validation: true (it sets how "
                              "many validation events score a model)")
        if isinstance(n, bool) or not isinstance(n, int) or not 1 <= n <= 60:
            raise ConfigError(f"validation_events must be an integer in [1, 60] (of the recover "
                              f"suite's 60 validation events), got {n!r}")
    if "action_log_std" in meta:
        from .exploration import check_action_log_std
        meta["action_log_std"] = check_action_log_std(meta["action_log_std"])
    if not isinstance(meta.setdefault("reward_kwargs", {}) or {}, dict):
        raise ConfigError(f"reward_kwargs must be a mapping, got {meta['reward_kwargs']!r}")
    for key, value in RUN_DEFAULTS.items():
        meta.setdefault(key, value)
    meta["env_kwargs"] = meta.get("env_kwargs") or {}
    if not isinstance(meta["env_kwargs"], dict):
        raise ConfigError(f"env_kwargs must be a mapping, got {meta['env_kwargs']!r}")
    if meta["reward_kwargs"]:
        if meta["reward"] != "kpi":
            raise ConfigError("reward_kwargs are the weights of reward: kpi; set reward: kpi or drop them")
        from .reward import check_reward_kwargs
        check_reward_kwargs(meta["reward_kwargs"])
    for d in (meta, algo_kwargs):
        for k in (k for k in INTEGERS if k in d):
            d[k] = _integer(d[k], k, INTEGERS[k])
    for k in FRACTIONS:
        if k in algo_kwargs and not (is_finite_number(algo_kwargs[k]) and 0.0 <= algo_kwargs[k] <= 1.0):
            raise ConfigError(f"{k} must be a number in [0, 1], got {algo_kwargs[k]!r}")
    _check_episodic(algo_kwargs.get("train_freq"), meta.get("n_envs", 1))
    return meta, algo_kwargs


def _check_episodic(train_freq: Any, n_envs: int) -> None:
    """SB3 trains per episode (``train_freq: [k, episode]``) with one environment only."""
    if isinstance(train_freq, tuple) and len(train_freq) == 2 and train_freq[1] == "episode" \
            and n_envs != 1:
        raise ConfigError(f"train_freq {list(train_freq)} (per episode) needs n_envs: 1 "
                          f"(or --n-envs 1; SB3 trains per episode with one environment only), "
                          f"got n_envs {n_envs}")


def _integer(value: Any, key: str, lo: int) -> int:
    """``value`` as an int (YAML writes 1e6 as a float) if it is a whole number >= ``lo``."""
    try:
        number = float(value)
    except (TypeError, ValueError):
        number = None
    if isinstance(value, bool) or number is None or not number.is_integer():
        raise ConfigError(f"{key} must be an integer, got {value!r}")
    if number < lo:
        raise ConfigError(f"{key} must be >= {lo}, got {int(number)}")
    return int(number)


def signature_keys(fn, skip: tuple[str, ...] = ("self",)) -> tuple[str, ...]:
    """The named keyword arguments of ``fn``."""
    kinds = (inspect.Parameter.POSITIONAL_OR_KEYWORD, inspect.Parameter.KEYWORD_ONLY)
    return tuple(k for k, p in inspect.signature(fn).parameters.items()
                 if p.kind in kinds and k not in skip)


def check_sb3(algo: str, env_id: str, meta: dict, algo_kwargs: dict) -> None:
    """The keys of ``split``'s output against what they are passed to: the algorithm's
    constructor, ``VecNormalize`` and the environment's constructor, and ``action_log_std``
    against the algorithm (ConfigError naming the key)."""
    from stable_baselines3.common.vec_env import VecNormalize
    for key in algo_kwargs:
        if key in SET_BY_TRAIN:
            raise ConfigError(f"{key} is set by rotordrop train ({SET_BY_TRAIN[key]}), not in the config")
    check_keys(f"{algo} config", algo_kwargs,
               list(dict.fromkeys([k for k in signature_keys(algo_class(algo).__init__)
                                   if k not in SET_BY_TRAIN] + list(META_KEYS))))
    if "action_log_std" in meta and (algo != "ppo" or algo_kwargs.get("use_sde")):
        raise ConfigError(f"action_log_std sets the per-entry log std of PPO's Gaussian policy: it "
                          f"needs --algo ppo without use_sde (got --algo {algo}"
                          f"{', use_sde: true' if algo_kwargs.get('use_sde') else ''})")
    if isinstance(meta["normalize"], dict):
        check_keys("normalize (VecNormalize arguments)", meta["normalize"],
                   signature_keys(VecNormalize.__init__, skip=("self", "venv")))
    check_keys(f"env_kwargs ({env_id} arguments)", meta["env_kwargs"], env_arguments(env_id))


def env_arguments(env_id: str) -> tuple[str, ...]:
    """The constructor keyword arguments of a registered environment."""
    import gymnasium as gym
    from gymnasium.envs.registration import load_env_creator
    import rotordrop_env  # noqa: F401  (registers the ids)
    return signature_keys(load_env_creator(gym.spec(env_id).entry_point).__init__)


def dump_yaml(data: dict, path: str | Path) -> None:
    Path(path).write_text(_yaml().safe_dump(data, sort_keys=False))
