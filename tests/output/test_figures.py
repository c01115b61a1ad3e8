"""Figure helpers: the animation's one palette, a laid-out figure saved without a re-layout."""

import io

import numpy as np
import pytest
from matplotlib.figure import Figure

from dextar.output.figures import _one_palette, _packed, png_bytes, svg_bytes, tight_layout


def test_frames_share_one_palette_and_keep_their_colours():
    rng = np.random.default_rng(3)
    still = np.full((60, 80, 3), 255, np.uint8)
    still[20:22, :] = (0, 0, 0)
    frames = []
    for k in range(6):  # a moving orange square with soft edges over the still part
        f = still.copy()
        f[10:20, 5 + 10 * k:15 + 10 * k] = (255, 127, 14)
        f[9, 5 + 10 * k:15 + 10 * k] = (255, 200, 150)
        frames.append(f)
    frames[3][40:45, 40:45] = rng.integers(0, 256, (5, 5, 3), dtype=np.uint8)  # many colours
    opaque = [np.concatenate([f, np.full(f.shape[:2] + (1,), 255, np.uint8)], -1)
              for f in frames]  # as the canvas gives them
    images = _one_palette([_packed(f) for f in opaque])
    assert len(images) == 6 and all(im.mode == "P" for im in images)
    assert len({bytes(im.getpalette()) for im in images}) == 1  # one palette
    for f, im in zip(frames, images, strict=True):
        back = np.asarray(im.convert("RGB"))
        # the few colours of a drawing are exact (white stays white, not PIL's 252)
        plain = np.ones(f.shape[:2], bool)
        plain[40:45, 40:45] = False
        assert np.array_equal(back[plain], f[plain])
    # the noisy patch: every pixel takes its nearest palette colour
    pal = np.asarray(images[3].getpalette(), int).reshape(-1, 3)
    patch = frames[3][40:45, 40:45].reshape(-1, 1, 3).astype(int)
    best = ((patch - pal[None]) ** 2).sum(-1).min(axis=1)
    got = ((patch[:, 0] - np.asarray(images[3].convert("RGB"))[40:45, 40:45].reshape(-1, 3))
           ** 2).sum(-1)
    assert np.array_equal(got, best)


def test_pixels_are_packed_as_one_integer_a_colour():
    rgba = np.random.default_rng(5).integers(0, 256, (7, 9, 4), dtype=np.uint8)
    want = (rgba[..., 0].astype(np.int64) + (rgba[..., 1].astype(np.int64) << 8)
            + (rgba[..., 2].astype(np.int64) << 16))
    assert np.array_equal(_packed(rgba), want)  # the alpha byte left out
    assert np.array_equal(_packed(rgba[:, ::2]), want[:, ::2])  # a view that is not contiguous


@pytest.mark.slow
def test_a_laid_out_figure_saves_the_same_bytes_without_its_layout_engine():
    def figure():
        fig = Figure(figsize=(3, 2))
        ax = fig.subplots()
        ax.plot([0, 1], [0, 2], label=r"$\varphi$")
        ax.set_xlabel("time")
        ax.legend()
        return fig

    plain = figure()
    plain.tight_layout()
    ours = figure()
    tight_layout(ours)
    assert plain.get_layout_engine() is not None  # matplotlib's placeholder: a second draw
    assert ours.get_layout_engine() is None
    assert png_bytes(ours, dpi=50) == png_bytes(plain, dpi=50)
    assert b"<svg" in svg_bytes(ours)
    assert io.BytesIO(png_bytes(ours, dpi=50)).read(8) == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize("total_s, frames", [(1.0, 41), (0.768, 41), (0.001, 41), (0.0, 41),
                                             (60.0, 500), (60.0, 2), (8 * 3600.0, 2),
                                             (40 * 60.0, 41), (41 * 60.0, 41), (1e9, 41)])
def test_the_animation_plays_in_real_time_within_a_gifs_delays(total_s, frames):
    """Never more frames than asked; frames every whole number of centiseconds from 20 ms
    (browsers play shorter delays slowly) to 60 s (a GIF's delay field ends at 655 s), the
    first and last samples shown, the motion's time played within 5 ms (20 ms for a motion
    shorter than that) up to ``frames - 1`` delays of 60 s, sped up past them (a 1e9 s
    motion had asked for 1.7e7 frames of 60 s: the run hung)."""
    from dextar.output.figures import ANIMATION_PAUSE_MS, _real_time_frames, _speedup

    t = np.linspace(0.0, total_s, 2001)
    index, delays = _real_time_frames(t, frames)
    if total_s == 0.0:  # no motion: one still frame
        assert list(index) == [0] and delays == [ANIMATION_PAUSE_MS]
        return
    assert index[0] == 0 and index[-1] == len(t) - 1 and len(index) == len(delays)
    assert len(index) <= frames
    assert delays[-1] == ANIMATION_PAUSE_MS
    inner = delays[:-1]
    assert all(20 <= d <= 60_000 and d % 10 == 0 for d in inner)
    speedup = _speedup(1e3 * total_s, frames)
    if total_s <= (frames - 1) * 60.0:
        assert speedup == 1.0
        if total_s >= 0.02:
            assert abs(sum(inner) - 1e3 * total_s) <= 5.0
    else:  # sped up: every frame the longest delay, the motion in that many times less
        assert speedup > 1.0 and inner == [60_000] * (frames - 1)
        assert sum(inner) * speedup == pytest.approx(1e3 * total_s, rel=1e-12)
        assert list(index) == sorted(set(index))  # evenly spread, each sample once
