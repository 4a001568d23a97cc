"""Episode view: one labelled frame per call, drawn with Pillow (no plotting library per frame).

The frame shows the rotor orbit at both retainer planes (clearance circle, half-clearance whirl
radius, AMB stator circle, the trace since the fault and the present position), the contact
force since the fault, and the numbers a person watching a drop asks for: time since the fault,
friction coefficient μ, rotor speed, contact force (now and peak), whirl state (net backward
orbit revolutions, latched backward-whirl flag), and where the environment has them the support
damping and the AMB state.

The renderer keeps only numbers (one row per control step); fonts, the static background and a
"human" window are rebuilt on demand, so a pickled or deep-copied environment draws the same
frames as the original.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

#: one recorded row per control step (SI units, NaN where the environment lacks the quantity)
COLUMNS = ("t", "force", "speed", "rev1", "rev2", "whirl", "damping1", "damping2", "amb_power",
           "controller_on")
(T, FORCE, SPEED, REV1, REV2, WHIRL, DAMP1, DAMP2, POWER, CTRL) = map(COLUMNS.index, COLUMNS)

WIDTH, HEIGHT = 768, 432                    # multiples of 16: MP4 encoders take them unscaled
ORBIT = 248                                 # side of an orbit panel [px]
ORBIT_TOP = 58
PANELS = (12, 12 + ORBIT + 14)              # left edge of the RB1 and RB2 orbit panels
FORCE_BOX = (52, 338, WIDTH - 14, HEIGHT - 26)   # contact-force trace: left, top, right, bottom
TEXT_X = PANELS[1] + ORBIT + 18
TRAIL = 10                                  # most recent steps drawn bold

#: the numbers beside the orbits (then "damping" and "AMB" where the environment has them)
LABELS = ("friction μ", "rotor speed", "contact force", "  peak so far", "whirl so far",
          "  net backward revs")
LINE = 28                                   # their spacing [px]

WHITE, BLACK, GREY, LIGHT = (255, 255, 255), (20, 20, 20), (120, 120, 120), (225, 225, 225)
RED, GREEN = (200, 30, 30), (30, 130, 50)
PLANE_COLOURS = ((31, 119, 180), (255, 127, 14))     # RB1, RB2
PALE = tuple(tuple(int(255 - 0.35 * (255 - c)) for c in col) for col in PLANE_COLOURS)


class Renderer:
    """Records the episode (``add`` per step) and draws it (``draw``)."""

    def __init__(self, mode: str, title: str, episode_time: float, n_steps: int,
                 samples_per_step: int = 1, damping: bool = False, amb: bool = False):
        self.mode = mode
        self.title = title
        self.labels = LABELS + (("damping [kN s/m]",) if damping else ()) + (("AMB",) if amb else ())
        self.episode_time = episode_time
        self.rows = np.full((n_steps + 1, len(COLUMNS)), np.nan)
        self.n = 0
        #: the rotor axis at the retainer planes (x1, y1, x2, y2 [m]; a flexible rotor's
        #: elastic deflection included) at the monitor samples, samples_per_step per step
        self.orbit = np.full((n_steps * samples_per_step + 1, 4), np.nan)
        self.n_orbit = 0
        self.trail = TRAIL * samples_per_step
        self.friction = math.nan
        self.geometry = (0.0, 0.0)          # (clearance, air gap) [m] of this episode
        self._cache: dict = {}              # fonts, background, human window: never copied

    def __getstate__(self) -> dict:
        state = dict(self.__dict__)
        state["_cache"] = {}
        return state

    # ------------------------------------------------------------------------ recording --
    def reset(self, friction: float, clearance: float, air_gap: float) -> None:
        """Start a new episode view (μ and the circles of the scene)."""
        self.n = self.n_orbit = 0
        self.rows[:] = np.nan
        self.orbit[:] = np.nan
        self.friction = float(friction)
        self.geometry = (float(clearance), float(air_gap))

    def add(self, row, orbit: np.ndarray) -> None:
        """One step's values in :data:`COLUMNS` order, and the rotor axis at the retainer
        planes (x1, y1, x2, y2) at the step's monitor samples ((k, 4))."""
        if self.n == self.rows.shape[0]:    # stepping on after the episode's end
            self.rows = _grow(self.rows)
        while self.n_orbit + len(orbit) > self.orbit.shape[0]:
            self.orbit = _grow(self.orbit)
        self.rows[self.n] = row
        self.n += 1
        self.orbit[self.n_orbit:self.n_orbit + len(orbit)] = orbit
        self.n_orbit += len(orbit)

    @property
    def recorded(self) -> np.ndarray:
        """The rows recorded in this episode, (n, len(COLUMNS))."""
        return self.rows[:self.n]

    # -------------------------------------------------------------------------- drawing --
    def draw(self) -> np.ndarray | None:
        img = self.frame()
        if self.mode == "rgb_array":
            return img
        self._show(img)
        return None

    def frame(self) -> np.ndarray:
        """The present frame, (HEIGHT, WIDTH, 3) uint8."""
        from PIL import ImageDraw
        img = self._background().copy()
        d = ImageDraw.Draw(img)
        rows = self.recorded
        if len(rows):
            self._orbits(d, self.orbit[:self.n_orbit])
            self._force(img, d, rows)
        self._labels(img, rows[-1] if len(rows) else np.full(len(COLUMNS), np.nan))
        return np.asarray(img)

    def _fonts(self) -> dict[str, "Glyphs"]:
        fonts = self._cache.get("fonts")
        if fonts is None:
            fonts = self._cache["fonts"] = {k: Glyphs(_font(size, bold)) for k, (size, bold) in
                                            dict(title=(17, True), big=(15, True), text=(13, False),
                                                 small=(11, False)).items()}
        return fonts

    def _background(self):
        """Everything that does not change during the episode (drawn once per geometry)."""
        key = ("background", self.geometry)
        img = self._cache.get(key)
        if img is not None:
            return img
        from PIL import Image, ImageDraw
        f = {k: g.font for k, g in self._fonts().items()}
        img = Image.new("RGB", (WIDTH, HEIGHT), WHITE)
        d = ImageDraw.Draw(img)
        d.text((12, 8), self.title, fill=BLACK, font=f["title"])
        c, gap = self.geometry
        scale = self._orbit_scale()
        for k, left in enumerate(PANELS):
            cx, cy = left + ORBIT / 2, ORBIT_TOP + ORBIT / 2
            d.rectangle((left, ORBIT_TOP, left + ORBIT, ORBIT_TOP + ORBIT), outline=LIGHT)
            d.line((left, cy, left + ORBIT, cy), fill=LIGHT)
            d.line((cx, ORBIT_TOP, cx, ORBIT_TOP + ORBIT), fill=LIGHT)
            for radius, colour, width in ((gap, RED, 1), (c, BLACK, 2), (0.5 * c, LIGHT, 1)):
                r = radius * scale
                d.ellipse((cx - r, cy - r, cx + r, cy + r), outline=colour, width=width)
            d.text((left, ORBIT_TOP - 19), f"orbit at RB{k + 1}", fill=PLANE_COLOURS[k], font=f["big"])
        d.text((PANELS[0] + ORBIT, ORBIT_TOP - 17), f"clearance {c * 1e6:.0f} µm",
               fill=BLACK, font=f["small"], anchor="ra")
        d.text((PANELS[1] + ORBIT, ORBIT_TOP - 17), f"stator {gap * 1e6:.0f} µm",
               fill=RED, font=f["small"], anchor="ra")
        left, top, right, bottom = FORCE_BOX
        d.rectangle(FORCE_BOX, outline=LIGHT)
        d.text((left, top - 18), "contact force (peak of the two planes)", fill=BLACK, font=f["text"])
        for frac in (0.0, 0.5, 1.0):
            x = left + frac * (right - left)
            d.text((x, bottom + 3), f"{frac * self.episode_time * 1e3:.0f} ms",
                   fill=GREY, font=f["small"], anchor="ma")
        d.text((left - 4, bottom), "0", fill=GREY, font=f["small"], anchor="rs")
        for k, name in enumerate(self.labels):
            d.text((TEXT_X, ORBIT_TOP - 4 + k * LINE), name, fill=GREY, font=f["text"])
        self._cache[key] = img
        return img

    def _orbit_scale(self) -> float:
        """Pixels per metre: the stator circle fills the panel with a small margin."""
        return 0.5 * ORBIT / (1.08 * max(self.geometry[1], self.geometry[0], 1e-9))

    def _orbits(self, d, orbit: np.ndarray) -> None:
        scale = self._orbit_scale()
        cy = ORBIT_TOP + ORBIT / 2
        n, trail = len(orbit), self.trail
        for k, left in enumerate(PANELS):
            cx = left + ORBIT / 2
            x, y = orbit[:, 2 * k], orbit[:, 2 * k + 1]
            pts = np.empty((n, 2))
            pts[:, 0] = cx + x * scale
            pts[:, 1] = cy - y * scale
            np.clip(pts[:, 0], left, left + ORBIT, out=pts[:, 0])     # stay in the panel
            np.clip(pts[:, 1], ORBIT_TOP, ORBIT_TOP + ORBIT, out=pts[:, 1])
            flat = pts.ravel().tolist()
            if n > trail:
                d.line(flat[:2 * (n - trail + 1)], fill=PALE[k], width=1)
            recent = flat[-2 * trail:]
            if len(recent) >= 4:
                d.line(recent, fill=PLANE_COLOURS[k], width=2)
            x, y = flat[-2:]
            d.ellipse((x - 4, y - 4, x + 4, y + 4), fill=PLANE_COLOURS[k])

    def _force(self, img, d, rows: np.ndarray) -> None:
        left, top, right, bottom = FORCE_BOX
        f_max = _nice_ceiling(float(np.nanmax(rows[:, FORCE], initial=0.0)))
        x = left + rows[:, T] / self.episode_time * (right - left)
        y = bottom - rows[:, FORCE] / f_max * (bottom - top)
        pts = np.column_stack([np.minimum(x, right), np.maximum(y, top)]).ravel().tolist()
        if len(pts) >= 4:
            d.line(pts, fill=BLACK, width=1)
        self._fonts()["small"].draw(img, (left - 4, top), _axis_text(f_max), GREY, "r")

    def _labels(self, img, row: np.ndarray) -> None:
        f = self._fonts()
        f["title"].draw(img, (WIDTH - 14, 9), f"t = {_num(row[T] * 1e3, '.1f')} ms after the fault",
                        BLACK, "r")
        revs = max(row[REV1], row[REV2]) if not np.isnan(row[REV1]) else math.nan
        whirl = row[WHIRL] > 0.0
        peak = float(np.nanmax(self.recorded[:, FORCE], initial=0.0)) if self.n else math.nan
        values = [(_num(self.friction, ".2f"), BLACK),
                  (f"{_num(row[SPEED] * 30 / math.pi, ',.0f')} rpm", BLACK),
                  (_force_text(row[FORCE]), BLACK),
                  (_force_text(peak), BLACK),
                  ("BACKWARD" if whirl else "none", RED if whirl else GREEN),
                  (_num(revs, ".1f"), RED if whirl else BLACK)]
        if not np.isnan(row[DAMP1]):
            values.append((f"{_num(row[DAMP1] * 1e-3, '.1f')} / {_num(row[DAMP2] * 1e-3, '.1f')}",
                           BLACK))
        if not np.isnan(row[POWER]):
            state = ("levitating" if row[CTRL] > 0 else "power back") if row[POWER] > 0 else "off"
            values.append((state, GREEN if row[CTRL] > 0 else BLACK))
        for k, (value, colour) in enumerate(values):
            f["big"].draw(img, (WIDTH - 14, ORBIT_TOP - 4 + k * LINE), value, colour, "r")

    def _show(self, img: np.ndarray) -> None:
        """Show the frame in a matplotlib window ("human" mode)."""
        window = self._cache.get("window")
        if window is None:
            import matplotlib
            import matplotlib.pyplot as plt
            if matplotlib.get_backend().lower() == "agg":
                from gymnasium import logger
                logger.warn("render_mode='human' with matplotlib's non-interactive 'agg' backend "
                            "shows nothing; set MPLBACKEND (e.g. TkAgg) or use 'rgb_array'")
            plt.ion()
            fig = plt.figure(figsize=(WIDTH / 100, HEIGHT / 100), dpi=100)
            ax = fig.add_axes((0, 0, 1, 1))
            ax.set_axis_off()
            window = self._cache["window"] = (plt, fig, ax.imshow(img))
        plt, fig, image = window
        image.set_data(img)
        fig.canvas.draw_idle()
        fig.canvas.flush_events()

    def close(self) -> None:
        window = self._cache.pop("window", None)
        if window is not None:
            window[0].close(window[1])


class Glyphs:
    """One font's characters rendered once as masks: a label then costs one paste per
    character instead of a FreeType layout (about 0.1 ms each), which keeps a frame near 1 ms.
    Kerning is dropped; for numbers and short labels it does not show."""

    PAD = 2

    def __init__(self, font):
        self.font = font
        ascent, descent = font.getmetrics()
        self.height = ascent + descent
        self.masks: dict[str, tuple] = {}

    def _glyph(self, ch: str) -> tuple:
        glyph = self.masks.get(ch)
        if glyph is None:
            from PIL import Image, ImageDraw
            advance = self.font.getlength(ch)
            mask = Image.new("L", (math.ceil(advance) + 2 * self.PAD, self.height))
            ImageDraw.Draw(mask).text((self.PAD, 0), ch, font=self.font, fill=255)
            glyph = self.masks[ch] = (mask, advance)
        return glyph

    def draw(self, img, xy: tuple[float, float], text: str, colour: tuple, align: str = "l") -> None:
        """``text`` with its top at ``y``; ``x`` is its left end, centre (``align="m"``) or
        right end (``"r"``)."""
        glyphs = [self._glyph(ch) for ch in text]
        x, y = xy
        if align != "l":
            width = sum(g[1] for g in glyphs)
            x -= width if align == "r" else 0.5 * width
        for mask, advance in glyphs:
            img.paste(colour, (round(x) - self.PAD, round(y)), mask)
            x += advance


def _font(size: int, bold: bool):
    """DejaVu Sans (shipped with matplotlib: it has μ and Ω), else Pillow's default font."""
    from PIL import ImageFont
    try:
        import matplotlib
        name = "DejaVuSans-Bold.ttf" if bold else "DejaVuSans.ttf"
        return ImageFont.truetype(str(Path(matplotlib.get_data_path()) / "fonts" / "ttf" / name), size)
    except (ImportError, OSError):
        return ImageFont.load_default(size)


def _num(value: float, fmt: str) -> str:
    return "–" if value is None or not math.isfinite(value) else format(value, fmt)


def _force_text(force: float) -> str:
    if not math.isfinite(force):
        return "–"
    return f"{force * 1e-3:.2f} kN" if force >= 1000.0 else f"{force:.0f} N"


def _grow(a: np.ndarray) -> np.ndarray:
    return np.concatenate([a, np.full_like(a, np.nan)])


def _axis_text(force: float) -> str:
    return f"{force * 1e-3:g} kN" if force >= 1000.0 else f"{force:g} N"


def _nice_ceiling(value: float) -> float:
    """The axis top for a force peak: 1, 2 or 5 x 10^k N above it (at least 100 N)."""
    value = max(value, 100.0)
    base = 10.0 ** math.floor(math.log10(value))
    return next(m * base for m in (1.0, 2.0, 5.0, 10.0) if m * base >= value)
