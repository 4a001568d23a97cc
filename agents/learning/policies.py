"""Learned policies (SB3 model + VecNormalize statistics) and name resolution for the CLI.

A learned policy is a directory written by ``rotordrop train`` (``model.zip``,
``vecnormalize.pkl``, ``config.yaml``) or its ``best/`` (``best_model.zip``,
``vecnormalize.pkl``), a model zip with those files next to it, or a policy
shipped in ``agents/policies/`` (``<name>.zip``, ``<name>.pkl``, ``<name>.json``; the name
starts with the algorithm: ``ppo-damping``). It answers ``predict`` like a controller.

A self-contained zip (:mod:`agents.sb3_policy`: what ``rotordrop train`` writes as ``model.zip``
and ``best/best_model.zip``, and what ships) carries its normalisation and residual itself: it
is run as it is, and the statistics next to it are not applied a second time.
"""
from __future__ import annotations

import json
import os
import pickle
import re
from dataclasses import dataclass, field
from functools import cached_property
from importlib import resources
from pathlib import Path

import numpy as np

from ..control.controllers import (BASELINES, controller_class, controller_env_kwargs, make_baseline,
                                   make_controller)
from ..control.plant import Plant
from .hyperparams import ALGOS as ALGO_NAMES, algo_class, parse_literal
from ..control.residual import RESIDUAL_SCALE, residual_action
from ..sb3_policy import FrameStack, current_env_id, frame_stack_of, export_self_contained, is_self_contained


#: the training schedules a zip pickles with the Python it was saved under; acting needs none of
#: them, and replacing them keeps a load from warning that it cannot unpickle them (SB3's
#: documented way to load a model for inference)
ACTING_ONLY = {"learning_rate": 0.0, "lr_schedule": lambda _: 0.0, "clip_range": lambda _: 0.0}


def shipped_dir() -> Path:
    return Path(str(resources.files("agents") / "policies"))


def shipped_names() -> list[str]:
    return sorted(p.stem for p in shipped_dir().glob("*.json")
                  if p.with_suffix(".zip").is_file())


@dataclass
class LearnedPolicy:
    """A trained model with its observation normalisation; ``predict`` as in SB3."""
    name: str
    algo: str
    env_id: str
    env_kwargs: dict
    model: object
    vecnormalize: object | None
    meta: dict = field(default_factory=dict)
    residual: str | dict | None = None   # baseline (a name, or {law, gains}) the policy corrects
    residual_scale: float = RESIDUAL_SCALE
    base: object | None = None
    source: str | None = None            # the path it was loaded from
    given_env_id: str | None = None      # the env id given at load (a plain SB3 zip records none)
    frame_stack: int | None = None       # observations the network sees at once (None: inferred)
    self_contained: bool | None = None   # normalisation and residual inside the zip (None: look)

    def __post_init__(self):
        if self.self_contained is None:
            self.self_contained = is_self_contained(self.model)
        if self.self_contained:
            self.frame_stack = self.model.policy.stack.n
        elif self.frame_stack is None:                  # a model still on its training env
            self.frame_stack = frame_stack_of(self.model.get_env())

    @cached_property
    def stack(self) -> FrameStack:
        """The observations the network sees at once, stacked as in training."""
        return FrameStack(self.frame_stack)

    def __reduce__(self):
        """Pickled as where it was loaded from (SB3 models and their statistics do not pickle):
        a Ray task of ``rotordrop benchmark --backend ray`` loads it again on its node."""
        if self.source is None:
            raise TypeError(f"policy {self.name} was not loaded from a file and cannot be pickled")
        return _reload, (self.source, self.name, self.given_env_id)

    def bound(self, plant: Plant) -> "LearnedPolicy":
        """Ready to drive the environment described by ``plant`` (checks that its observations
        and actions are the ones the policy was trained with; builds the residual's base)."""
        self.check_spaces(plant)
        if self.residual is not None:
            self.base = make_baseline(self.residual, plant)
        return self

    def predict(self, observation, state=None, episode_start=None, deterministic: bool = True):
        if self.residual is not None and self.base is None:
            raise RuntimeError(f"{self.name} corrects the {self.residual} controller: call "
                               f".bound(Plant.from_env(env)) before predict")
        if self.self_contained:                 # normalisation, network, residual: one path
            return self.model.policy.act(observation, state, episode_start, deterministic, self.base)
        raw = np.asarray(observation, dtype=np.float32)
        obs = self.stack(raw, episode_start)
        obs = self.vecnormalize.normalize_obs(obs) if self.vecnormalize is not None else obs
        action, state = self.model.predict(obs, state=state, episode_start=episode_start,
                                           deterministic=deterministic)
        if self.residual is not None:
            action = residual_action(self.base, raw, action, self.residual_scale, episode_start)
        return action, state

    def check_spaces(self, plant: Plant) -> None:
        """ValueError unless ``plant``'s environment has the policy's observation and action sizes."""
        for what, space, n in (("observations", self.model.observation_space, len(plant.obs_names)),
                               ("actions", self.model.action_space,
                                2 if plant.discrete else len(plant.action_names))):
            size = space.shape[0] if space.shape else space.n
            size //= self.frame_stack if what == "observations" else 1
            if size != n and self.given_env_id is not None and plant.env_id == self.env_id:
                raise ValueError(f"policy {self.name} has {size} {what}, --env {self.env_id} has "
                                 f"{n}: pass the --env the model was trained on")
            if size != n:
                raise ValueError(f"policy {self.name} was trained on {self.env_id} with {size} "
                                 f"{what}; {plant.env_id} has {n}: evaluate it on {self.env_id}")

    @classmethod
    def load(cls, path: str | Path, name: str | None = None, env_id: str | None = None,
             check_env: bool = True) -> "LearnedPolicy":
        """The policy at ``path``; ``env_id`` names the environment it was trained on when
        nothing next to it records one (a plain SB3 ``model.save`` zip: its env kwargs are then
        the environment's defaults); with ``check_env`` a recorded env id other than ``env_id``
        is a ValueError (evaluate passes False: it may run a policy in another env id with the
        same spaces)."""
        path = Path(path)
        if env_id is not None:
            import gymnasium as gym
            import rotordrop_env  # noqa: F401  (registers the ids)
            if env_id not in gym.registry:
                known = sorted(k for k in gym.registry if k.startswith("RotorDrop-"))
                raise ValueError(f"--env {env_id!r} is not a registered environment; one of "
                                 f"{', '.join(known)}")
        if path.is_dir() and not (path / "model.zip").is_file() and (path / "best_model.zip").is_file():
            path = path / "best_model.zip"                  # a run's best/
        if path.is_dir():
            model_path = path / "model.zip"
            vn_paths = [path / "vecnormalize.pkl"]
            meta = _read_meta(path / "config.yaml")
        elif path.suffix == ".zip":
            model_path = path
            vn_paths = _stats_candidates(path)
            meta = (_read_meta(path.with_suffix(".json")) or _read_meta(path.parent / "config.yaml")
                    or _read_meta(path.parent.parent / "config.yaml"))      # a run's best/
        else:
            raise FileNotFoundError(f"{path} is neither a training directory nor a model .zip")
        if not model_path.is_file():
            raise FileNotFoundError(f"no model at {model_path}" + (
                " (nor best_model.zip: a run's best/)" if path.is_dir() else ""))
        algo = meta.get("algo") or _algo_from_zip(model_path)
        model = algo_class(algo).load(str(model_path), device="cpu", custom_objects=ACTING_ONLY)
        contained = is_self_contained(model)
        inside = model.policy.rotordrop if contained else {}
        given, env_id = env_id, meta.get("env_id") or inside.get("env_id")
        env_id = current_env_id(env_id) if env_id is not None else None
        if check_env and env_id is not None and given is not None and given != env_id:
            raise ValueError(f"{model_path} was trained on {env_id} (recorded next to it or in "
                             f"the zip), not --env {given}: leave out --env or pass {env_id}")
        env_id = env_id or given
        if env_id is None:
            raise FileNotFoundError(f"cannot tell which environment {model_path} was trained on: "
                                    f"no config.yaml or .json next to it; pass --env ID (e.g. "
                                    f"--env RotorDrop-Damping-v1)")
        hp = meta.get("hyperparams", {})
        env_kwargs = dict(meta.get("env_kwargs") or hp.get("env_kwargs")
                          or inside.get("env_kwargs") or {})
        task = env_id.split("-")[1].lower() if env_id.count("-") >= 2 else "policy"
        if contained:                       # normalisation and residual are inside the zip
            vn, settings = None, model.policy.rotordrop
        else:
            vn, settings = _load_stats(model_path, vn_paths, hp.get("normalize", False)), hp
        return cls(name or meta.get("name") or f"{algo}-{task}", algo, env_id, env_kwargs, model,
                   vn, meta, settings.get("residual"),
                   float(settings.get("residual_scale") or RESIDUAL_SCALE),
                   source=str(path.resolve()), given_env_id=given,
                   frame_stack=settings.get("frame_stack"), self_contained=contained)


def _reload(source: str, name: str, env_id: str | None = None) -> LearnedPolicy:
    return LearnedPolicy.load(source, name=name, env_id=env_id)


def _stats_candidates(model_zip: Path) -> list[Path]:
    """Where the VecNormalize statistics of a model zip may be, in order: ``<stem>.pkl`` (a
    shipped policy), SB3's checkpoint naming (``rl_model_vecnormalize_<N>_steps.pkl`` next to
    ``rl_model_<N>_steps.zip``), ``vecnormalize.pkl`` in its directory (a run, its ``best/``)."""
    checkpoint = re.fullmatch(r"(.+)_(\d+)_steps\.zip", model_zip.name)
    return [model_zip.with_suffix(".pkl"),
            *([model_zip.with_name(f"{checkpoint[1]}_vecnormalize_{checkpoint[2]}_steps.pkl")]
              if checkpoint else []),
            model_zip.parent / "vecnormalize.pkl"]


def _load_stats(model_path: Path, candidates: list[Path], normalize):
    """The first statistics file of ``candidates``; FileNotFoundError when the run normalised
    its observations (hyperparameter ``normalize``) and none is there."""
    found = next((p for p in candidates if p.is_file()), None)
    if found is None:
        norm = parse_literal(normalize, "normalize")
        if norm is True or (isinstance(norm, dict) and norm.get("norm_obs", True)):
            raise FileNotFoundError(
                f"{model_path} was trained with observation normalisation, but its VecNormalize "
                f"statistics are missing: looked for {', '.join(str(p) for p in candidates)}")
        return None
    with open(found, "rb") as fh:
        vn = pickle.load(fh)
    vn.training = False
    return vn


def _read_meta(path: Path) -> dict:
    if not path.is_file():
        return {}
    if path.suffix == ".json":
        return json.loads(path.read_text())
    from .hyperparams import load_yaml
    return load_yaml(path.read_text()) or {}


def _algo_from_zip(path: Path) -> str:
    """The algorithm from the zip's policy class, else from its name (``<algo>-...``)."""
    from ..sb3_policy import zip_algo
    found = zip_algo(path)
    if found is not None:
        return found
    for a in ALGO_NAMES:
        if a in path.stem.lower():
            return a
    raise ValueError(f"cannot tell the algorithm of {path}: name it <algo>-..., or keep the "
                     f"config.yaml written by rotordrop train next to it")


def load_shipped(name: str) -> LearnedPolicy:
    path = shipped_dir() / f"{name}.zip"
    if not path.is_file():
        raise KeyError(f"no shipped policy {name!r}; shipped: {', '.join(shipped_names()) or 'none'}")
    return LearnedPolicy.load(path, name=name)


def resolve(spec: str, plant: Plant | None = None, env_id: str | None = None):
    """A baseline name, a controller class spec (``module:Class``, ``file.py:Class``), a shipped
    policy name or a path -> (controller-or-policy, env_id | None). ``env_id`` (``--env``): the
    environment of a path that records none (a plain SB3 zip, :meth:`LearnedPolicy.load`).

    Controllers need the ``plant`` of the environment they will drive (without it: None).
    """
    cls = controller_class(spec)
    if cls is not None:
        return (make_controller(cls, plant) if plant is not None else None), None
    pol = _learned(spec, env_id)
    return (pol.bound(plant) if plant is not None else pol), pol.env_id


def _learned(spec: str, env_id: str | None) -> LearnedPolicy:
    """The learned policy ``spec`` names, a shipped one or a path (not a controller: the callers
    asked :func:`controller_class` first); KeyError for anything else."""
    if spec in shipped_names():
        return load_shipped(spec)
    if Path(spec).exists():
        return LearnedPolicy.load(spec, env_id=env_id, check_env=False)
    raise KeyError(f"--policy {spec!r} is not a baseline ({', '.join(BASELINES)}), a shipped "
                   f"policy ({', '.join(shipped_names()) or 'none shipped'}), an existing path or "
                   f"a controller class (package.module:Class, file.py:Class)")


def run_label(spec: str) -> str:
    """A short label of a policy path that tells runs apart: the run directory, with ``/best``
    for its best model (``runs/a/best/best_model.zip`` -> ``a/best``, ``runs/a/model.zip`` and
    ``runs/a`` -> ``a``, ``x/ppo-7.zip`` -> ``ppo-7``; a relative ``model.zip`` names the
    current directory)."""
    path = Path(os.path.abspath(spec))
    if path.suffix != ".zip":
        return path.name
    if path.name == "best_model.zip" and path.parent.name == "best":
        return f"{path.parent.parent.name}/best"
    return path.parent.name if path.name == "model.zip" else path.stem


def policy_label(spec: str, policy: LearnedPolicy) -> str:
    """The display name of a learned policy: a shipped one's name, else ``name@run`` (:func:`run_label`)."""
    return policy.name if spec in shipped_names() else f"{policy.name}@{run_label(spec)}"


def actor_for(spec: str, env_id: str | None = None):
    """What ``rotordrop evaluate`` runs for ``--policy spec`` (``--env env_id``): (make_actor(plant),
    env id, env kwargs, display name, designed). A shipped policy's name, a baseline or a
    controller class (``designed``: True; ``--env`` is required) or a path; the env id and
    kwargs are the policy's own unless ``env_id`` is given."""
    if spec not in shipped_names():          # (a shipped name is never a controller's)
        cls = controller_class(spec)
        if cls is not None:
            if env_id is None:
                raise ValueError(f"--env is required for the controller {spec!r}")
            return ((lambda plant: make_controller(cls, plant)), env_id,
                    controller_env_kwargs(cls, env_id), cls.name, True)
    policy = _learned(spec, env_id)
    return (policy.bound, env_id or policy.env_id, dict(policy.env_kwargs),
            policy_label(spec, policy), False)


def export_policy(source: str | Path, out: str | Path, env_id: str | None = None) -> Path:
    """``rotordrop export-policy``: the policy at ``source`` (a run directory, its ``best/``, a
    checkpoint or model zip with its statistics next to it, a plain SB3 zip with ``env_id``, or a
    shipped name) as one self-contained zip (:func:`agents.sb3_policy.export_self_contained`) at
    ``out``."""
    pol = (load_shipped(str(source)) if str(source) in shipped_names()
           else LearnedPolicy.load(source, env_id=env_id))
    return export_learned(pol, out)


def export_zoo(source: str | Path, folder: str | Path, env_id: str | None = None) -> Path:
    """The policy at ``source`` (as :func:`export_policy`) laid out as an rl-zoo3 run in
    ``folder`` (``<algo>/<env id>.zip`` and ``<algo>/<env id>/config.yml`` with its env kwargs),
    so that ``python -m rl_zoo3.enjoy --algo ALGO --env ID --gym-packages rotordrop_env -f
    FOLDER --exp-id -1`` plays it. The zip is self-contained: no VecNormalize is applied."""
    from .hyperparams import dump_yaml
    pol = (load_shipped(str(source)) if str(source) in shipped_names()
           else LearnedPolicy.load(source, env_id=env_id))
    run = Path(folder) / pol.algo
    (run / pol.env_id).mkdir(parents=True, exist_ok=True)
    dump_yaml({"env_kwargs": pol.env_kwargs, "normalize": False}, run / pol.env_id / "config.yml")
    return export_learned(pol, run / f"{pol.env_id}.zip")


def export_learned(pol: LearnedPolicy, out: str | Path) -> Path:
    """A loaded :class:`LearnedPolicy` as a self-contained zip (see :func:`export_policy`)."""
    if pol.self_contained:
        pol.model.save(out)
        return Path(out).with_suffix(".zip")
    return export_self_contained(pol.model, pol.vecnormalize, out, env_id=pol.env_id,
                                 env_kwargs=pol.env_kwargs, residual=pol.residual,
                                 residual_scale=pol.residual_scale)
