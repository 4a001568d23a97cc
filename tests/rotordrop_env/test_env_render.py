"""The episode view: what a frame shows, Gymnasium's RecordVideo, and video files."""
import gymnasium as gym
import numpy as np
import pytest

from rotordrop_env import render as R
from rotordrop_env.video import mp4_available, write_video


def _episode(env_id, friction, steps, **kw):
    env = gym.make(env_id, render_mode="rgb_array", overrides={"contact.friction": friction},
                   terminate_on_failure=False, **kw)
    env.reset(seed=0)
    infos = [env.step(np.zeros(env.action_space.shape, np.float32))[4] for _ in range(steps)]
    return env, infos


def _pixels(img, box, colour, tol=40):
    """How many pixels of ``img[box]`` are within ``tol`` of ``colour``."""
    left, top, right, bottom = box
    patch = img[top:bottom, left:right].astype(int)
    return int((np.abs(patch - np.array(colour)).sum(axis=2) < tol).sum())


def _value_box(k):
    """The right-aligned value of label line k."""
    top = R.ORBIT_TOP - 4 + k * R.LINE
    return (R.TEXT_X, top, R.WIDTH, top + R.LINE - 6)


def test_the_view_records_what_the_env_reports():
    env, infos = _episode("RotorDrop-Damping-v1", 0.3, 30)
    u = env.unwrapped
    rows = u._renderer.recorded
    assert rows.shape == (31, len(R.COLUMNS))                      # reset + 30 steps
    np.testing.assert_allclose(rows[1:, R.T], [i["time_s"] for i in infos], atol=1e-12)
    assert rows[1:, R.FORCE].tolist() == [i["contact_force_N"] for i in infos]
    speed = u.obs_names.index("rotor_speed")
    assert rows[-1, R.SPEED] == pytest.approx(u._b.obs[speed] * u.obs_scale[speed])
    assert rows[0, R.DAMP1] == u.scene.support.damping                # damper starts at C_s
    assert np.isnan(rows[:, R.POWER]).all()                         # no AMB in this task


@pytest.mark.parametrize("friction,whirl", [(0.1, False), (0.5, True)])
def test_a_frame_shows_orbits_at_both_planes_and_the_whirl_state(friction, whirl):
    env, infos = _episode("RotorDrop-Passive-v1", friction, 120)
    assert bool(infos[-1]["backward_whirl"]) is whirl
    img = env.render()
    assert img.shape == (R.HEIGHT, R.WIDTH, 3) and img.dtype == np.uint8
    for k, left in enumerate(R.PANELS):                             # each plane's orbit, own colour
        box = (left, R.ORBIT_TOP, left + R.ORBIT, R.ORBIT_TOP + R.ORBIT)
        assert _pixels(img, box, R.PLANE_COLOURS[k]) > 40             # recent trace and dot
        assert _pixels(img, box, R.PALE[k], 20) > 100                   # the trace since the fault
        assert _pixels(img, box, R.PLANE_COLOURS[1 - k]) == 0
    state = _value_box(R.LABELS.index("whirl so far"))
    assert (_pixels(img, state, R.RED) > 20) is whirl
    assert (_pixels(img, state, R.GREEN) > 20) is not whirl
    left, top, right, bottom = R.FORCE_BOX                          # force trace drawn
    assert _pixels(img, (left + 1, top + 1, right - 1, bottom - 1), R.BLACK, 60) > 50


def test_frames_differ_as_the_numbers_change_and_the_amb_line_appears():
    env, _ = _episode("RotorDrop-Full-v1", 0.3, 10, command="continuous")
    first = env.render()
    env.step(np.zeros(6, np.float32))
    second = env.render()
    header = (R.WIDTH // 2, 0, R.WIDTH, R.ORBIT_TOP - 22)          # "t = ... ms after the fault"
    l, t, r, b = header
    assert not np.array_equal(first[t:b, l:r], second[t:b, l:r])
    assert len(env.unwrapped._renderer.labels) == len(R.LABELS) + 2   # damping and AMB lines


def test_record_video_writes_an_mp4_of_every_step(tmp_path):
    pytest.importorskip("moviepy")
    if not mp4_available():
        pytest.skip("no ffmpeg")
    import imageio.v2 as imageio
    from gymnasium.wrappers import RecordVideo
    env = RecordVideo(gym.make("RotorDrop-Damping-v1", render_mode="rgb_array",
                               episode_time=0.012), tmp_path / "videos", episode_trigger=lambda e: e == 0,
                      disable_logger=True)
    env.reset(seed=0)
    done = False
    while not done:
        *_, term, trunc, _ = env.step(env.action_space.sample())
        done = term or trunc
    assert len(env.recorded_frames) == 13                           # reset + 12 steps
    env.close()
    files = sorted((tmp_path / "videos").glob("*.mp4"))
    assert len(files) == 1
    frames = [f for f in imageio.get_reader(files[0])]      # (its len() is inf)
    # moviepy's encoder may leave out the last frame (its clip duration is 12 / fps)
    assert len(frames) in (12, 13) and frames[0].shape == (R.HEIGHT, R.WIDTH, 3)


@pytest.mark.parametrize("suffix", [".gif", ".mp4"])
def test_write_video_round_trip(tmp_path, suffix):
    if suffix == ".mp4" and not mp4_available():
        pytest.skip("no ffmpeg")
    env, _ = _episode("RotorDrop-Passive-v1", 0.3, 4)
    frames = [env.render()]
    for _ in range(3):
        env.step(np.zeros(1, np.float32))
        frames.append(env.render())
    path = write_video(frames, tmp_path / f"drop{suffix}", fps=10)
    if suffix == ".gif":
        from PIL import Image
        with Image.open(path) as im:
            assert im.n_frames == 4 and im.size == (R.WIDTH, R.HEIGHT)
    else:
        import imageio.v2 as imageio
        assert sum(1 for _ in imageio.get_reader(path)) == 4
    with pytest.raises(ValueError, match="must end in .mp4 or .gif"):
        write_video(frames, tmp_path / "drop.avi", fps=10)
    with pytest.raises(ValueError, match="no frames"):
        write_video([], tmp_path / "drop.gif", fps=10)


def test_evaluate_video_writes_the_first_episode(tmp_path, monkeypatch):
    """``rotordrop evaluate --video``: the first episode, one frame per step and the reset; a
    GIF through Pillow when ffmpeg is missing."""
    from agents.benchmarking.evaluate import evaluate
    from rotordrop_env import video
    for suffix in ([".mp4"] if mp4_available() else []) + [".gif"]:
        monkeypatch.setattr(video, "default_suffix", lambda s=suffix: s)
        report = evaluate("ppo-damping", None, 1, tmp_path / suffix[1:], plots=False,
                          compare_passive=False, video=True)
        path = tmp_path / suffix[1:] / report["video"]
        assert path.name == f"episode{suffix}" and report["episodes"][0]["length"] == 60
        if suffix == ".gif":
            from PIL import Image
            with Image.open(path) as im:
                assert im.n_frames == 61
        else:
            import imageio.v2 as imageio
            assert sum(1 for _ in imageio.get_reader(path)) == 61
