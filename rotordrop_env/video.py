"""Writing rendered frames to a video file: MP4 through imageio-ffmpeg (installed with the
``video`` extra, which also makes Gymnasium's ``RecordVideo`` work), or an animated GIF through
Pillow when no ffmpeg is available."""
from __future__ import annotations

from pathlib import Path
from typing import Sequence

import numpy as np

FORMATS = (".mp4", ".gif")


def mp4_available() -> bool:
    """True when imageio-ffmpeg (with its ffmpeg binary) can be imported."""
    try:
        import imageio_ffmpeg
        imageio_ffmpeg.get_ffmpeg_exe()
    except (ImportError, RuntimeError):
        return False
    return True


def default_suffix() -> str:
    """``.mp4`` where ffmpeg is available, else ``.gif``."""
    return ".mp4" if mp4_available() else ".gif"


def write_video(frames: Sequence[np.ndarray], path: str | Path, fps: float) -> Path:
    """Write ``frames`` ((H, W, 3) uint8 each) to ``path`` (.mp4 or .gif) at ``fps``."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in FORMATS:
        raise ValueError(f"video file {str(path)!r} must end in {' or '.join(FORMATS)}")
    if not len(frames):
        raise ValueError("no frames to write: run an episode with render_mode='rgb_array'")
    if not fps > 0:
        raise ValueError(f"fps = {fps!r} must be > 0")
    path.parent.mkdir(parents=True, exist_ok=True)
    if suffix == ".gif":
        _write_gif(frames, path, fps)
    else:
        _write_mp4(frames, path, fps)
    return path


def _write_gif(frames, path: Path, fps: float) -> None:
    """One palette for all frames, from the last (the fullest) frame: the views use few
    colours, so this is fast and does not flicker."""
    from PIL import Image
    palette = Image.fromarray(np.asarray(frames[-1], dtype=np.uint8)).quantize(colors=128)
    images = [Image.fromarray(np.asarray(f, dtype=np.uint8)).quantize(
        palette=palette, dither=Image.Dither.NONE) for f in frames]
    images[0].save(path, save_all=True, append_images=images[1:], loop=0,
                   duration=max(int(round(1000.0 / fps)), 20))


def _write_mp4(frames, path: Path, fps: float) -> None:
    if not mp4_available():
        raise ValueError(f"writing {path.name} needs imageio-ffmpeg: pip install "
                         "'rotordrop[video]' (or write a .gif, which needs only Pillow)")
    import imageio_ffmpeg
    height, width = np.shape(frames[0])[:2]
    writer = imageio_ffmpeg.write_frames(str(path), (width, height), fps=fps, quality=7,
                                         macro_block_size=16, ffmpeg_log_level="error")
    writer.send(None)
    try:
        for frame in frames:
            writer.send(np.ascontiguousarray(frame, dtype=np.uint8))
    finally:
        writer.close()
