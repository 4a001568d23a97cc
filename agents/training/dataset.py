"""``rotordrop dataset``: seeded episodes of a controller or policy as a Minari data set.

Any ``--policy`` that ``rotordrop evaluate`` runs (a baseline or designed controller name, a
shipped policy, a training directory or model zip, a ``module:Class`` controller) is resolved
exactly as evaluate resolves it (:func:`agents.learning.policies.actor_for`) and run on the environment
built as evaluate builds it (:func:`agents.benchmarking.rollout.merge_env_kwargs`: the policy's env kwargs,
then the user's, scenario randomisation on unless ``randomize=False``, episodes run their
full length, the KPI monitor at 0.2 ms). Episode ``i`` is ``env.reset(seed=seed + i)``; a
controller is built afresh for every episode, as in evaluate and the benchmark.

The episodes are written with Minari's :func:`minari.create_dataset_from_buffers` in its
``arrow`` format (Minari's ``DataCollector`` wrapper would need jax, ``minari[create]``, to
buffer steps, and its default ``hdf5`` format h5py; the arrow format needs only pyarrow). The
data set lives at ``<root>/<dataset id>`` with ``root`` = ``--out`` (set as
``MINARI_DATASETS_PATH`` for the write, so that nothing goes to ``~/.minari``); load it with
``MINARI_DATASETS_PATH=<root>`` and ``minari.load_dataset(<dataset id>)``, or with
:func:`load` here.

What is stored (docs/datasets.md):

* ``observations`` (T+1 rows, float32, the env's normalised observations), ``actions`` (T rows,
  the action space's dtype), ``rewards``, ``terminations``, ``truncations``;
* ``infos``: one column per scalar number the env reports in ``info``, T+1 rows (row 0 is the
  reset). The columns are chosen on the first episode and kept for all: the keys present at
  every step (bool columns stay bool, the others become float64; the environments report the
  same keys at reset and every step, the ``kpi_*`` as the episode's KPIs so far), and keys an
  env adds at the last step only (float64, NaN before the last row). A row where the env did
  not report a key holds NaN (False for a bool column); nested dicts are left out.
* episode metadata: ``seed`` (Minari's own field: ``env.reset(seed=...)`` of that episode),
  ``scenario`` (the scene values the episode ran, ``env.unwrapped.scenario``), ``kpis`` (the
  episode KPIs, ``kpi_`` prefix removed) and ``return``;
* data set metadata: ``rotordrop`` = policy, its display name, env id, env kwargs, seeds,
  info columns (and their kinds): everything :func:`replay` needs to run the episodes again.
"""
from __future__ import annotations

import math
import numbers
import os
import re
import shutil
import time
import warnings
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import numpy as np

#: Minari storage format (pyarrow; no h5py needed)
DATA_FORMAT = "arrow"
#: metadata key of everything rotordrop records about the data set
META_KEY = "rotordrop"
#: episodes held in memory before they are written
CHUNK = 100


def default_dataset_id(policy_name: str, env_id: str) -> str:
    """``rotordrop/<task>/<policy>-v0``: ``RotorDrop-Full-v1`` + ``whirl-brake`` ->
    ``rotordrop/full/whirl-brake-v0`` (the policy name reduced to letters, digits and dashes)."""
    task = env_id.split("-")[1].lower() if env_id.count("-") >= 2 else "env"
    name = re.sub(r"[^a-z0-9]+", "-", policy_name.lower()).strip("-") or "policy"
    return f"rotordrop/{task}/{name}-v0"


def parse_env_kwargs(items: list[str] | None) -> dict:
    """``["episode_time=0.05", "overrides={'contact.friction': 0.4}"]`` -> kwargs; values are
    Python literals (numbers, strings, True/False/None, lists, dicts), a bare word stays a
    string."""
    from ..learning.hyperparams import parse_literal
    kw: dict = {}
    for item in items or []:
        key, sep, text = item.partition("=")
        if not sep or not key.strip():
            raise ValueError(f"--env-kwarg expects KEY=VALUE, got {item!r}")
        try:
            value = parse_literal(text.strip(), key)
        except Exception:               # a bare word: a string (scene name, command...)
            value = text.strip()
        kw[key.strip()] = value
    return kw


@contextmanager
def datasets_root(root: str | Path | None):
    """``MINARI_DATASETS_PATH`` = ``root`` (absolute) inside the block, as it was afterwards."""
    if root is None:
        yield None
        return
    old = os.environ.get("MINARI_DATASETS_PATH")
    os.environ["MINARI_DATASETS_PATH"] = str(Path(root).resolve())
    try:
        yield Path(root).resolve()
    finally:
        if old is None:
            os.environ.pop("MINARI_DATASETS_PATH", None)
        else:
            os.environ["MINARI_DATASETS_PATH"] = old


# --------------------------------------------------------------------------- infos --
def _is_number(v) -> bool:
    return (isinstance(v, (bool, np.bool_, numbers.Real, np.number))
            and not isinstance(v, (complex, np.complexfloating)))


def _is_bool(v) -> bool:
    return isinstance(v, (bool, np.bool_))


def info_columns(reset_info: dict, step_infos: list[dict]) -> dict[str, str]:
    """The info columns of a data set from its first episode: key -> ``"bool"`` or ``"float"``
    (module doc: the scalar numbers of every step, then those of the last step only)."""
    if not step_infos:
        return {}
    every = [k for k, v in step_infos[0].items()
             if all(k in i and _is_number(i[k]) for i in step_infos)]
    cols = {k: "bool" if all(_is_bool(i[k]) for i in step_infos) else "float" for k in every}
    for k, v in step_infos[-1].items():               # the episode KPIs (last step only)
        if k not in cols and (_is_number(v) or v is None):
            cols[k] = "float"
    return cols


def info_arrays(columns: dict[str, str], infos: list[dict]) -> dict[str, np.ndarray]:
    """``infos`` (the reset's, then one per step) as one array per column; a missing or
    non-numeric value is NaN (False in a bool column)."""
    out = {}
    for k, kind in columns.items():
        if kind == "bool":
            out[k] = np.array([bool(i[k]) if _is_number(i.get(k)) else False for i in infos],
                              dtype=bool)
        else:
            out[k] = np.array([float(i[k]) if _is_number(i.get(k)) else math.nan for i in infos],
                              dtype=np.float64)
    return out


# ------------------------------------------------------------------------ collection --
@dataclass
class Collected:
    """The raw episodes of one run (before they are written)."""
    seed: int
    observations: np.ndarray          # (T+1, n_obs)
    actions: np.ndarray               # (T, ...) in the action space's dtype
    rewards: np.ndarray
    terminations: np.ndarray
    truncations: np.ndarray
    infos: list[dict]                 # reset info, then one per step
    scenario: dict | None
    kpis: dict


def resolve_actor(policy: str, env_id: str | None, env_kwargs: dict | None = None,
                  randomize: bool = True):
    """(make_actor(plant), env id, env kwargs, display name) as ``rotordrop evaluate`` resolves
    and builds them; ValueError / KeyError naming the parameter on bad input."""
    from rotordrop_env import ENV_IDS
    from ..benchmarking.rollout import merge_env_kwargs
    from ..learning.policies import actor_for
    if env_id is not None and env_id not in ENV_IDS:
        raise ValueError(f"--env {env_id!r} is not a rotor-drop environment; known: "
                         f"{', '.join(ENV_IDS)}")
    make_actor, env_id, base_kwargs, name, _ = actor_for(policy, env_id)
    if env_id not in ENV_IDS:
        raise ValueError(f"--env {env_id!r} is not a rotor-drop environment; known: "
                         f"{', '.join(ENV_IDS)}")
    return make_actor, env_id, merge_env_kwargs(base_kwargs, env_kwargs or {}, randomize), name


def run_episode(env, plant, actor, seed: int) -> Collected:
    """One episode, acting as :func:`agents.benchmarking.rollout.run_episodes` does (``predict`` on a batch of
    one, ``episode_start`` on the first step, deterministic)."""
    obs, info = env.reset(seed=int(seed))
    observations, actions, rewards, terms, truncs, infos = [obs], [], [], [], [], [info]
    start, running = np.ones(1, dtype=bool), np.zeros(1, dtype=bool)
    dtype = env.action_space.dtype
    while True:
        action, _ = actor.predict(obs[None, :], episode_start=start, deterministic=True)
        start = running
        a = np.asarray(action[0])
        obs, reward, terminated, truncated, step_info = env.step(a)
        observations.append(obs)
        actions.append(a.astype(dtype))
        rewards.append(float(reward))
        terms.append(bool(terminated))
        truncs.append(bool(truncated))
        infos.append(step_info)
        if terminated or truncated:
            break
    from ..benchmarking.rollout import final_kpis
    return Collected(int(seed), np.asarray(observations, dtype=env.observation_space.dtype),
                     np.asarray(actions, dtype=dtype), np.asarray(rewards, dtype=np.float64),
                     np.asarray(terms), np.asarray(truncs), infos,
                     dict(env.unwrapped.scenario), final_kpis(step_info))


def collect(make_actor, env_id: str, env_kwargs: dict, seeds, progress: bool = False):
    """Run one episode per seed (a controller anew each episode); yields :class:`Collected`."""
    from tqdm.auto import tqdm
    from ..control.controllers import Controller
    from ..control.plant import Plant, make_env
    env = make_env(env_id, **env_kwargs)
    try:
        plant = Plant.from_env(env)
        actor = None
        for s in tqdm(list(seeds), desc="episodes", unit="ep", disable=not progress):
            if actor is None or isinstance(actor, Controller):
                actor = make_actor(plant)
            yield run_episode(env, plant, actor, s)
    finally:
        env.close()


def _jsonable(value):
    """Numbers and containers as strict JSON types (numpy scalars -> Python, NaN and
    infinities -> None, as the project's reports write them)."""
    if isinstance(value, dict):
        return {str(k): _jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_jsonable(v) for v in value]
    if isinstance(value, np.ndarray):
        return _jsonable(value.tolist())
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


# --------------------------------------------------------------------------- writing --
def write_dataset(policy: str, env_id: str | None, episodes: int, out: str | Path,
                  seed: int = 0, env_kwargs: dict | None = None, dataset_id: str | None = None,
                  overwrite: bool = False, progress: bool = True) -> dict:
    """``rotordrop dataset``: ``episodes`` seeded episodes (seeds ``seed`` ... ``seed +
    episodes - 1``) of ``policy`` on ``env_id`` as the Minari data set ``dataset_id`` (default
    :func:`default_dataset_id`) under the root ``out``. ``env_kwargs`` go to ``gym.make`` over
    the policy's own (``randomize`` among them: default True, a scenario drawn per seed).
    Returns a summary (id, path, root, episodes, steps, seconds, load snippet)."""
    if not isinstance(episodes, numbers.Integral) or episodes < 1:
        raise ValueError(f"--episodes must be an integer >= 1, got {episodes!r}")
    if seed < 0:
        raise ValueError(f"--seed must be >= 0, got {seed}")
    user = dict(env_kwargs or {})
    randomize = user.pop("randomize", True)
    if not isinstance(randomize, bool):
        raise ValueError(f"--env-kwarg randomize must be True or False, got {randomize!r}")
    make_actor, env_id, kwargs, name = resolve_actor(policy, env_id, user, randomize)
    from ..control.controllers import is_controller_spec
    from ..benchmarking.rollout import check_actor
    if is_controller_spec(policy):
        check_actor(env_id, make_actor, kwargs)                 # fail fast: a user's class
    dataset_id = dataset_id or default_dataset_id(name, env_id)
    import minari
    from minari.dataset.minari_dataset import parse_dataset_id
    try:
        parse_dataset_id(dataset_id)
    except ValueError:
        raise ValueError(f"--name {dataset_id!r} is not a Minari dataset id: "
                         f"(namespace/)name-v<version>, e.g. rotordrop/full/whirl-brake-v0") from None
    root = Path(out).resolve()
    root.mkdir(parents=True, exist_ok=True)
    target = root / dataset_id
    if target.exists():
        if not overwrite:
            raise ValueError(f"--out: a data set {dataset_id!r} exists at {target}; pass "
                             f"--overwrite or another --name")
        shutil.rmtree(target)

    seeds = list(range(seed, seed + episodes))
    t0 = time.perf_counter()
    from minari.data_collector.episode_buffer import EpisodeBuffer
    from ..control.plant import make_env
    meta = dict(policy=policy, policy_name=name, env_id=env_id, env_kwargs=_jsonable(kwargs),
                user_env_kwargs=_jsonable(user), randomize=randomize, seeds=seeds,
                command=_command())
    ds, columns, steps, pending, extra = None, None, 0, [], []
    spec_env = make_env(env_id, **kwargs)          # its spec (id + kwargs): recover_environment
    try:
        with datasets_root(root), warnings.catch_warnings():
            warnings.filterwarnings("ignore", message=r".*(code_permalink|author|author_email|"
                                    r"description|eval_env|algorithm_name).*", category=UserWarning)
            for i, ep in enumerate(collect(make_actor, env_id, kwargs, seeds, progress)):
                if columns is None:
                    columns = info_columns(ep.infos[0], ep.infos[1:])
                pending.append(EpisodeBuffer(
                    id=i, seed=ep.seed, observations=ep.observations, actions=ep.actions,
                    rewards=list(ep.rewards), terminations=list(ep.terminations),
                    truncations=list(ep.truncations),
                    # lists: Minari's arrow storage cannot read back 1-D arrays (it records an
                    # empty shape for them)
                    infos={k: v.tolist() for k, v in info_arrays(columns, ep.infos).items()}))
                extra.append(dict(scenario=_jsonable(ep.scenario), kpis=_jsonable(ep.kpis),
                                  **{"return": float(ep.rewards.sum())}))
                if len(pending) == CHUNK or i == episodes - 1:     # bounded memory
                    if ds is None:
                        ds = minari.create_dataset_from_buffers(
                            dataset_id, pending, env=spec_env, algorithm_name=name,
                            author="rotordrop", data_format=DATA_FORMAT,
                            description=f"{episodes} seeded episodes of {name} on {env_id} "
                                        f"(rotordrop dataset)")
                    else:
                        ds.storage.update_episodes(pending)
                    ds.storage.update_episode_metadata(extra, range(i + 1 - len(extra), i + 1))
                    steps += sum(len(b) for b in pending)
                    pending, extra = [], []
            ds.storage.update_metadata({META_KEY: dict(meta, info_columns=columns)})
    except BaseException:
        shutil.rmtree(target, ignore_errors=True)               # no half-written data set
        raise
    finally:
        spec_env.close()
    run_s = time.perf_counter() - t0
    return dict(dataset_id=dataset_id, root=str(root), path=str(target), episodes=episodes,
                steps=steps, seeds=seeds, policy=name, env_id=env_id, run_s=run_s,
                episodes_per_s=episodes / run_s if run_s > 0 else math.inf,
                size_mb=_size_mb(target), info_columns=columns)


def _size_mb(path: Path) -> float:
    return sum(p.stat().st_size for p in path.rglob("*") if p.is_file()) / 2**20


def _command() -> str:
    import shlex
    import sys
    return " ".join(shlex.quote(a) for a in ["rotordrop", *sys.argv[1:]]) if sys.argv[1:] else ""


def load_snippet(dataset_id: str, root: str) -> str:
    return (f"MINARI_DATASETS_PATH={root} python3 -c \"import minari; "
            f"ds = minari.load_dataset('{dataset_id}'); print(ds.total_episodes, ds.total_steps)\"")


# --------------------------------------------------------------------------- reading --
def load(dataset: str | Path, root: str | Path | None = None):
    """A data set by id under ``root`` (default ``MINARI_DATASETS_PATH``, else Minari's
    ``~/.minari/datasets``), or by its directory (``<root>/<id>``, or its ``data/``), as
    ``minari.load_dataset`` opens it but without creating the root when it is absent.
    FileNotFoundError naming ``--dataset`` if there is none."""
    from minari.dataset.minari_dataset import MinariDataset
    if root is None:
        root = os.environ.get("MINARI_DATASETS_PATH") or Path("~/.minari/datasets").expanduser()
    for candidate in (Path(dataset), Path(dataset) / "data", Path(root) / dataset / "data"):
        if candidate.name == "data" and (candidate / "metadata.json").is_file():
            return MinariDataset(str(candidate))
    raise FileNotFoundError(f"--dataset {str(dataset)!r}: no Minari data set at that path nor "
                            f"under the root {root} (--root, MINARI_DATASETS_PATH)")


def rotordrop_meta(ds) -> dict:
    """The ``rotordrop`` metadata of a data set written by :func:`write_dataset`."""
    meta = ds.storage.metadata.get(META_KEY)
    if meta is None:
        raise ValueError(f"data set {ds.id} was not written by rotordrop dataset (no "
                         f"{META_KEY!r} metadata)")
    return meta


def episode_metadata(ds) -> list[dict]:
    """Per episode: ``seed``, ``scenario``, ``kpis``, ``return`` (and Minari's ``id``,
    ``total_steps``)."""
    return list(ds.storage.get_episode_metadata(ds.episode_indices))


def replay(ds, episode: int = 0) -> Collected:
    """Run episode ``episode`` of the data set again: same policy, env kwargs and seed."""
    meta = rotordrop_meta(ds)
    seed = episode_metadata(ds)[episode]["seed"]
    make_actor, env_id, kwargs, _ = resolve_actor(meta["policy"], meta["env_id"],
                                                  meta["user_env_kwargs"], meta["randomize"])
    for ep in collect(make_actor, env_id, kwargs, [seed]):
        return ep
    raise RuntimeError("no episode")                                   # pragma: no cover
