"""Self-contained policy zips: plain ``PPO.load`` / ``SAC.load`` / ``TD3.load`` (and
sb3-contrib's ``TQC.load`` / ``CrossQ.load``) act like the project's loader.

A policy trained by ``rotordrop train`` needs two things besides its network: the observation
normalisation (``VecNormalize`` statistics) and, for a residual policy (config ``residual:``),
the baseline controller whose action it corrects. :func:`export_self_contained` writes a zip
whose policy class (one of :data:`POLICY_CLASSES`, subclasses of SB3's own) carries both:

* the statistics as buffers of the policy's ``state_dict`` (``obs_mean``, ``obs_var``), applied
  in ``predict`` exactly as ``VecNormalize.normalize_obs`` does (float64, clipped, to float32);
* the residual's baseline by name and scale, applied in ``predict`` as
  :func:`agents.control.residual.residual_action` does, on a :class:`~agents.control.plant.Plant` of the
  training environment (``env_id`` and ``env_kwargs`` in the zip).

SB3 saves the policy class by reference, so loading the zip imports this module (the
``rotordrop`` package must be installed). A baseline that keeps per-episode state
(``Controller.memoryless`` False) cannot be rebuilt from single observations: the zip then
refuses ``predict`` under plain SB3, with a message that says how to load it.

The exported policy is for acting (``predict``); to continue training, resume the run from its
checkpoints (``rotordrop train --resume``).
"""
from __future__ import annotations

import base64
import copy
import json
import pickletools
import zipfile
from pathlib import Path
from typing import Any

import numpy as np
import torch as th
from stable_baselines3.common.policies import ActorCriticPolicy
from stable_baselines3.sac.policies import SACPolicy
from stable_baselines3.td3.policies import TD3Policy

try:                                    # TQC and CrossQ are sb3-contrib's (the rl extra installs it)
    from sb3_contrib.crossq.policies import CrossQPolicy
    from sb3_contrib.tqc.policies import TQCPolicy
except ImportError:                     # pragma: no cover
    TQCPolicy = CrossQPolicy = None

#: the ``policy_kwargs`` entry that carries the environment, normalisation and residual
KEY = "rotordrop"


class FrameStack:
    """The last ``n`` observations side by side, newest last, as SB3's ``VecFrameStack`` builds
    them in training: a row whose ``episode_start`` is set (or the first call) starts from zeros.
    Observations ``(d,)`` or ``(batch, d)`` in, ``(n d,)`` or ``(batch, n d)`` out."""

    def __init__(self, n: int):
        self.n = int(n)
        self.frames: np.ndarray | None = None

    def __call__(self, obs: np.ndarray, episode_start=None) -> np.ndarray:
        if self.n == 1:
            return obs
        single = obs.ndim == 1
        rows = obs.reshape(1, -1) if single else obs
        d = rows.shape[1]
        if self.frames is None or self.frames.shape != (rows.shape[0], self.n * d):
            self.frames = np.zeros((rows.shape[0], self.n * d), dtype=rows.dtype)
        elif episode_start is not None:
            self.frames[np.broadcast_to(np.asarray(episode_start, dtype=bool).reshape(-1),
                                        (rows.shape[0],))] = 0.0
        self.frames[:, :-d] = self.frames[:, d:]
        self.frames[:, -d:] = rows
        return self.frames[0].copy() if single else self.frames.copy()


def frame_stack_of(venv) -> int:
    """The ``VecFrameStack`` depth in a VecEnv's wrapper chain (1 without one)."""
    from stable_baselines3.common.vec_env import VecFrameStack
    while venv is not None:
        if isinstance(venv, VecFrameStack):
            return int(venv.stacked_obs.n_stack)
        venv = getattr(venv, "venv", None)
    return 1


class SelfContained:
    """Mixin of the exported policy classes (see the module docstring).

    ``rotordrop`` (a ``policy_kwargs`` entry): ``env_id``, ``env_kwargs``, ``normalize``
    (``{"epsilon", "clip_obs"}`` or None), ``residual`` (baseline name or None),
    ``residual_scale``, ``memoryless`` (the baseline keeps no per-episode state),
    ``frame_stack`` (observations the network sees at once, default 1: pass ``episode_start``
    to ``predict`` so that a new episode starts from an empty stack).
    """

    def _setup_rotordrop(self, meta: dict[str, Any] | None) -> None:
        self.rotordrop = dict(meta or {})
        self.stack = FrameStack(self.rotordrop.get("frame_stack", 1))
        n = int(np.prod(self.observation_space.shape))
        self.register_buffer("obs_mean", th.zeros(n, dtype=th.float64))
        self.register_buffer("obs_var", th.ones(n, dtype=th.float64))
        self._base = None

    # ------------------------------------------------------------------------ acting --
    def normalize_obs(self, raw: np.ndarray) -> np.ndarray:
        """``VecNormalize.normalize_obs`` of the training run, from the buffers."""
        norm = self.rotordrop.get("normalize")
        if not norm:
            return raw
        mean, var = self.obs_mean.cpu().numpy(), self.obs_var.cpu().numpy()
        clip = norm["clip_obs"]
        return np.clip((raw - mean) / np.sqrt(var + norm["epsilon"]), -clip, clip).astype(np.float32)

    def network_predict(self, observation, state=None, episode_start=None, deterministic=False):
        """SB3's own ``predict`` of the network (normalised observations in, its actions out)."""
        return super().predict(observation, state, episode_start, deterministic)

    def act(self, observation, state, episode_start, deterministic: bool, base):
        """Raw environment observations in, environment actions out: normalisation, network,
        then the residual on ``base`` (a baseline controller, or None without a residual)."""
        raw = np.asarray(observation, dtype=np.float32)
        action, state = self.network_predict(self.normalize_obs(self.stack(raw, episode_start)),
                                             state, episode_start, deterministic)
        if base is not None:
            from .control.residual import residual_action
            action = residual_action(base, raw, action, float(self.rotordrop["residual_scale"]),
                                     episode_start)
        return action, state

    def predict(self, observation, state=None, episode_start=None, deterministic=False):
        """SB3's ``predict`` as ``rotordrop evaluate`` runs the policy (:meth:`act`); the
        residual's baseline is built for the training environment on first use."""
        residual = self.rotordrop.get("residual")
        if residual and not self.rotordrop.get("memoryless"):
            raise RuntimeError(
                f"this policy corrects the {residual!r} controller, which keeps per-episode state "
                "that single observations do not carry, so plain SB3 cannot run it; load it with "
                "agents.learning.policies.LearnedPolicy.load(path).bound(Plant.from_env(env)), or run "
                "`rotordrop evaluate --policy path`")
        return self.act(observation, state, episode_start, deterministic,
                        self.training_base() if residual else None)

    def training_base(self):
        """The residual's baseline on the training environment (``env_id``, ``env_kwargs``)."""
        if self._base is None:
            from .control.controllers import make_baseline
            from .control.plant import plant_of
            self._base = make_baseline(self.rotordrop["residual"],
                                       plant_of(current_env_id(self.rotordrop["env_id"]),
                                                **self.rotordrop.get("env_kwargs", {})))
        return self._base


class RotorDropActorCriticPolicy(SelfContained, ActorCriticPolicy):
    """PPO's ``MlpPolicy`` with the normalisation and residual inside (see module docstring)."""

    def __init__(self, *args, rotordrop: dict | None = None, **kwargs):
        super().__init__(*args, **kwargs)
        self._setup_rotordrop(rotordrop)


class RotorDropSACPolicy(SelfContained, SACPolicy):
    """SAC's ``MlpPolicy`` with the normalisation and residual inside."""

    def __init__(self, *args, rotordrop: dict | None = None, **kwargs):
        super().__init__(*args, **kwargs)
        self._setup_rotordrop(rotordrop)


class RotorDropTD3Policy(SelfContained, TD3Policy):
    """TD3's ``MlpPolicy`` with the normalisation and residual inside."""

    def __init__(self, *args, rotordrop: dict | None = None, **kwargs):
        super().__init__(*args, **kwargs)
        self._setup_rotordrop(rotordrop)


#: SB3 policy class -> its self-contained subclass
POLICY_CLASSES = {ActorCriticPolicy: RotorDropActorCriticPolicy, SACPolicy: RotorDropSACPolicy,
                  TD3Policy: RotorDropTD3Policy}

if TQCPolicy is not None:
    class RotorDropTQCPolicy(SelfContained, TQCPolicy):
        """TQC's (sb3-contrib) ``MlpPolicy`` with the normalisation and residual inside."""

        def __init__(self, *args, rotordrop: dict | None = None, **kwargs):
            super().__init__(*args, **kwargs)
            self._setup_rotordrop(rotordrop)

    POLICY_CLASSES[TQCPolicy] = RotorDropTQCPolicy

if CrossQPolicy is not None:
    class RotorDropCrossQPolicy(SelfContained, CrossQPolicy):
        """CrossQ's (sb3-contrib) ``MlpPolicy`` with the normalisation and residual inside."""

        def __init__(self, *args, rotordrop: dict | None = None, **kwargs):
            super().__init__(*args, **kwargs)
            self._setup_rotordrop(rotordrop)

    POLICY_CLASSES[CrossQPolicy] = RotorDropCrossQPolicy


#: the module of a plain SB3 model's policy class -> its algorithm
PLAIN_MODULES = {"stable_baselines3.common.policies": "ppo", "stable_baselines3.sac.policies": "sac",
                 "stable_baselines3.td3.policies": "td3", "sb3_contrib.tqc.policies": "tqc",
                 "sb3_contrib.crossq.policies": "crossq"}
#: the self-contained policy classes -> their algorithm
EXPORTED_ALGOS = {"RotorDropActorCriticPolicy": "ppo", "RotorDropSACPolicy": "sac",
                  "RotorDropTD3Policy": "td3", "RotorDropTQCPolicy": "tqc",
                  "RotorDropCrossQPolicy": "crossq"}


def current_env_id(env_id: str) -> str:
    """The registered id of a task: a zip exported under a retired version (``RotorDrop-Full-v0``,
    which Gymnasium refuses as deprecated) names the current version of the same task, whose
    observations and actions are the same (docs/environments.md, version history)."""
    from rotordrop_env import ENV_IDS
    task = str(env_id).rsplit("-v", 1)[0]
    current = [i for i in ENV_IDS if i.rsplit("-v", 1)[0] == task]
    return current[0] if env_id not in ENV_IDS and current else env_id


def zip_algo(path: str | Path) -> str | None:
    """The algorithm of an SB3 model zip (plain or self-contained) from its saved policy class,
    read without loading the model; None for a policy class of no supported algorithm.
    ValueError if ``path`` is not an SB3 model zip."""
    try:
        with zipfile.ZipFile(path) as z:
            cls = json.loads(z.read("data")).get("policy_class", {})
    except (OSError, KeyError, ValueError, zipfile.BadZipFile) as exc:
        raise ValueError(f"{path} is not a Stable-Baselines3 model zip ({exc})") from exc
    module = cls.get("__module__")
    if module != __name__:
        return PLAIN_MODULES.get(module)
    try:                          # the pickled reference names the class: read it, import nothing
        ops = pickletools.genops(base64.b64decode(cls.get(":serialized:", "")))
        names = {arg for _, arg, _ in ops if isinstance(arg, str)}
    except ValueError:
        return None
    return next((EXPORTED_ALGOS[n] for n in names if n in EXPORTED_ALGOS), None)


def _exported_class(policy) -> type:
    for base, cls in POLICY_CLASSES.items():
        if type(policy) in (base, cls):
            return cls
    raise ValueError(f"cannot export a {type(policy).__name__}: only the MlpPolicy of PPO, SAC, "
                     "TD3, TQC and CrossQ is supported")


def export_self_contained(model, vecnormalize, out_path: str | Path, *, env_id: str | None = None,
                          env_kwargs: dict | None = None, residual: str | None = None,
                          residual_scale: float | None = None, frame_stack: int = 1) -> Path:
    """Write ``model`` (a PPO / SAC / TD3 / TQC with an ``MlpPolicy``) as a zip that plain SB3 loads
    and runs like the project's loader: ``vecnormalize`` (a ``VecNormalize`` or None) and the
    ``residual`` baseline (name, ``residual_scale``) go inside the policy. ``env_id`` and
    ``env_kwargs`` name the training environment (the residual's plant); without ``env_id``
    all four are read from the model's own training env (its spec and its
    :class:`~agents.control.residual.ResidualAction` wrapper, if any). ``frame_stack``: the number of
    observations the network sees at once (the run's ``frame_stack``). The model passed in is
    left as it was."""
    from .control.controllers import BASELINES, baseline_name
    from .control.residual import RESIDUAL_SCALE, residual_of
    cls = _exported_class(model.policy)
    if env_id is None:
        venv = model.get_env()
        if venv is None:
            raise ValueError("export_self_contained: give env_id= (and env_kwargs, residual): "
                             "the model has no training environment to read them from")
        spec = venv.get_attr("spec", [0])[0]
        env_id, env_kwargs = spec.id, dict(spec.kwargs)
        residual, residual_scale = residual_of(venv)
    if residual is not None:
        baseline_name(residual)                 # ValueError naming the baselines
    norm = None
    if vecnormalize is not None and vecnormalize.norm_obs:
        norm = {"epsilon": float(vecnormalize.epsilon), "clip_obs": float(vecnormalize.clip_obs)}
    meta = dict(env_id=env_id, env_kwargs=copy.deepcopy(dict(env_kwargs or {})), normalize=norm,
                residual=residual,
                residual_scale=float(RESIDUAL_SCALE if residual_scale is None else residual_scale),
                memoryless=bool(residual is None or BASELINES[baseline_name(residual)].memoryless),
                frame_stack=int(frame_stack))
    policy, kwargs = _rebuilt(model, cls, meta)
    if norm is not None:
        policy.obs_mean.copy_(th.as_tensor(vecnormalize.obs_rms.mean, dtype=th.float64))
        policy.obs_var.copy_(th.as_tensor(vecnormalize.obs_rms.var, dtype=th.float64))
    return _save_with(model, policy, kwargs, out_path)


def save_plain(model, out_path: str | Path) -> Path:
    """The network of a self-contained ``model`` as SB3's own ``MlpPolicy`` zip: what training
    continues from (with the run's VecNormalize statistics and residual wrapper around the env)."""
    plain = {cls: base for base, cls in POLICY_CLASSES.items()}
    if type(model.policy) not in plain:
        raise ValueError(f"{type(model.policy).__name__} is not a self-contained rotordrop policy")
    return _save_with(model, *_rebuilt(model, plain[type(model.policy)], None), out_path)


def _rebuilt(model, cls: type, meta: dict | None) -> tuple:
    """(a ``cls`` policy with ``model``'s weights and optimizer state, its ``policy_kwargs``);
    ``meta``: the ``rotordrop`` entry of a self-contained class, None for SB3's own."""
    kwargs = {k: v for k, v in model.policy_kwargs.items() if k != KEY}
    if meta is not None:
        kwargs[KEY] = meta
    # on-policy algorithms pass gSDE to the policy outside policy_kwargs (off-policy ones inside)
    sde = {"use_sde": True} if getattr(model, "use_sde", False) and "use_sde" not in kwargs else {}
    policy = cls(model.observation_space, model.action_space, model.lr_schedule, **kwargs,
                 **sde).to(model.device)
    buffers = {"obs_mean", "obs_var"}
    state = {k: v for k, v in model.policy.state_dict().items() if k not in buffers}
    missing, unexpected = policy.load_state_dict(state, strict=False)
    if set(missing) - buffers or unexpected:
        raise ValueError(f"cannot rebuild {cls.__name__}: state_dict mismatch (missing {missing}, "
                         f"unexpected {unexpected})")
    if hasattr(model.policy, "optimizer"):
        policy.optimizer.load_state_dict(model.policy.optimizer.state_dict())
    return policy, kwargs


def _save_with(model, policy, kwargs: dict, out_path: str | Path) -> Path:
    """``model.save(out_path)`` with ``policy`` (and its ``policy_kwargs``) in place of its own
    (restored afterwards)."""
    out_path = Path(out_path)
    out_path.parent.mkdir(parents=True, exist_ok=True)
    saved = {k: getattr(model, k) for k in ("policy", "policy_class", "policy_kwargs")}
    try:
        model.policy, model.policy_class = policy, type(policy)
        model.policy_kwargs = kwargs
        model.save(out_path)
    finally:
        for k, v in saved.items():
            setattr(model, k, v)
    return out_path if out_path.suffix == ".zip" else out_path.with_suffix(".zip")


def is_self_contained(model) -> bool:
    """The model's policy applies its own normalisation and residual (an exported zip)."""
    return isinstance(model.policy, SelfContained)
