"""``rotordrop evaluate``: KPIs of a policy or baseline over seeded episodes, against passive.

Writes ``kpis.json`` (per-episode scenario and KPIs, and their summary, for the policy and for
the passive drop on the same seeds at the policy's control step, so that the returns compare;
strict JSON, null where a KPI is undefined) and ``orbits.png`` / ``contact_force.png`` / ``actions.png`` (first
episode, policy against passive); with ``video`` the first episode as ``episode.mp4`` (the
environment's labelled frames; ``episode.gif`` where no ffmpeg is installed).
"""
from __future__ import annotations

from pathlib import Path

from .benchmark import EPISODE_TIME, RELEVITATION_ENVS, check_power_return
from ..control.controllers import Passive
from ..learning.policies import actor_for
from .rollout import check_actor, merge_env_kwargs, run_episodes
from .score import fmt_or_dash, summarize, write_json


def _episode_rows(eps) -> list[dict]:
    """kpis.json's per-episode records: seed, return, length, the scenario the episode ran
    (the env's ``reset`` info) and the KPIs."""
    return [dict(seed=e.seed, reward=e.reward, length=e.length,
                 **({"scenario": e.scenario} if e.scenario is not None else {}),
                 **e.kpis) for e in eps]


def evaluate(policy: str, env_id: str | None, episodes: int, out: str | Path,
             env_kwargs: dict | None = None, seed: int = 0, plots: bool = True,
             compare_passive: bool = True, randomize: bool = True, video: bool = False) -> dict:
    """Run ``episodes`` seeded episodes of ``policy`` (and of the passive drop on the same
    scenarios). With ``randomize`` every seed draws a scenario from the env's randomisation
    ranges (keys given in ``env_kwargs["overrides"]`` stay fixed); episodes run their full
    length (``terminate_on_failure=False``) unless ``env_kwargs`` says otherwise."""
    if episodes < 1:
        raise ValueError(f"--episodes must be >= 1, got {episodes}")
    make_actor, env_id, base_kwargs, name, designed = actor_for(policy, env_id)
    from rotordrop_env import ENV_IDS
    if env_id not in ENV_IDS:
        raise ValueError(f"--env {env_id!r} is not a rotor-drop environment; known: {', '.join(ENV_IDS)}")
    if "power_return_time" in (env_kwargs or {}) and env_id not in RELEVITATION_ENVS:
        raise ValueError(f"--power-return-ms (power_return_time) applies to the re-levitation "
                         f"environments ({', '.join(RELEVITATION_ENVS)}) only, not {env_id}")
    kwargs = merge_env_kwargs(base_kwargs, env_kwargs or {}, randomize)
    if "power_return_time" in (env_kwargs or {}):
        check_power_return(kwargs["power_return_time"], "--power-return-ms",
                           kwargs.get("episode_time", EPISODE_TIME))     # the envs' default
    if designed:
        check_actor(env_id, make_actor, kwargs)                  # fail fast: a user's class
    seeds = list(range(seed, seed + episodes))
    eps = run_episodes(env_id, make_actor, seeds, kwargs, record=True)
    # the passive drop on the same scenarios, AMBs left off, at the policy's control step (the
    # return sums per-step rewards: it compares only at the same step)
    passive_kwargs = {k: v for k, v in kwargs.items() if k != "command"}
    passive = run_episodes(env_id, Passive, seeds, passive_kwargs, record=True) if compare_passive else []
    report = dict(policy=name, env_id=env_id, env_kwargs=kwargs, seeds=seeds,
                  summary=summarize(eps), episodes=_episode_rows(eps))
    if passive:
        report["passive_summary"] = summarize(passive)
        report["passive_episodes"] = _episode_rows(passive)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    if plots:
        from .plots import plot_episode_comparison
        report["figures"] = [p.name for p in plot_episode_comparison(
            eps[0], passive[0] if passive else None, name, out)]
    if video:
        report["video"] = _write_video(env_id, make_actor, seeds[0], kwargs, out)
    write_json(out / "kpis.json", report)
    report["out"] = str(out)
    return report


def _write_video(env_id: str, make_actor, seed: int, kwargs: dict, out: Path) -> str:
    """The first episode again, rendered (same seed, deterministic actor): ``episode.mp4``, or
    ``episode.gif`` without ffmpeg. Returns the file name."""
    from rotordrop_env.env import RotorDropEnv
    from rotordrop_env.video import default_suffix, write_video
    frames: list = []
    run_episodes(env_id, make_actor, [seed], {**kwargs, "render_mode": "rgb_array"}, frames=frames)
    path = write_video(frames, out / f"episode{default_suffix()}", RotorDropEnv.metadata["render_fps"])
    return path.name


def print_summary(report: dict) -> None:
    rows = [(report["policy"], report["summary"])]
    if "passive_summary" in report:
        rows.append(("passive", report["passive_summary"]))
    w = max(18, len(report["policy"]) + 2)
    dt = report["env_kwargs"].get("control_dt")
    print(f"{report['env_id']}, {report['summary']['episodes']} episodes (seeds "
          f"{report['seeds'][0]}..{report['seeds'][-1]})"
          + (f", control step {1e3 * dt:g} ms (passive at the same step)" if dt else ""))
    print(f"{'controller':{w}}{'whirl rate':>11}{'peak F [N]':>12}{'max disp [µm]':>15}"
          f"{'relev. rate':>12}{'relev. t [ms]':>14}{'effort':>9}{'return':>9}")
    for name, s in rows:
        t = s["relevitation_time_s"]
        print(f"{name:{w}}{fmt_or_dash(s['backward_whirl_rate'], '.2f'):>11}{fmt_or_dash(s['peak_contact_force_N'], '.0f'):>12}"
              f"{fmt_or_dash(s['max_displacement_um'], '.0f'):>15}{fmt_or_dash(s['relevitation_success_rate'], '.2f'):>12}"
              f"{fmt_or_dash(t * 1e3 if t is not None else None, '.1f'):>14}{fmt_or_dash(s['control_effort'], '.3g'):>9}"
              f"{fmt_or_dash(s['mean_return'], '.1f'):>9}")
    print(f"wrote {Path(report['out']) / 'kpis.json'}"
          + "".join(f", {f}" for f in report.get("figures", []))
          + (f", {report['video']}" if "video" in report else ""))

