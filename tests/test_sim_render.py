"""`urdftool sim --render`: pictures of each model at rest, visual and collision geometry."""

from __future__ import annotations

import pybullet  # noqa: F401 - the test extra has it: missing, this fails
from PIL import Image

from tests.conftest import run_urdftool
from tests.test_sim import arm


def _fraction(path, test) -> float:
    with Image.open(path) as image:
        data = image.convert("RGB").tobytes()
    pixels = [tuple(data[i:i + 3]) for i in range(0, len(data), 3)]
    return sum(1 for p in pixels if test(p)) / len(pixels)


def _red(pixel) -> bool:  # the arm's material is rgba 1 0 0 (shaded: dark to bright red)
    r, g, b = pixel
    return r > 60 and g < 0.35 * r and b < 0.35 * r


def _orange(pixel) -> bool:  # collision geometry is drawn in rgba 1 0.45 0.05
    r, g, b = pixel
    return r > 60 and 0.25 * r < g < 0.7 * r and b < 0.2 * r


def test_render_writes_both_pictures_of_the_right_size_with_the_robot_in_them(write, tmp_path):
    model = write(arm(), "arm.urdf")
    target = tmp_path / "pictures" / "arm.png"
    result = run_urdftool("sim", model, "--render", target, "--size", "240x180",
                          "--duration", "0.2")
    assert result.code == 0, result.out + result.err
    collision = tmp_path / "pictures" / "arm-collision.png"
    for path in (target, collision):
        assert path.is_file() and path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
        with Image.open(path) as image:
            assert image.size == (240, 180)
    # the robot stands out from the ground and the sky: a good part of the picture is its red
    # (visual) or orange (collision), and the other picture has none of that colour
    assert _fraction(target, _red) > 0.02
    assert _fraction(collision, _orange) > 0.02
    assert _fraction(target, _orange) < 0.002
    assert _fraction(collision, _red) < 0.002
    assert str(target) in result.out and str(collision) in result.out


def test_render_several_models_gives_one_picture_each_named_after_the_model(write, tmp_path):
    first = write(arm(), "first.urdf")
    second = write(arm(effort="0"), "sub/second.urdf")
    out = tmp_path / "out"
    out.mkdir()
    result = run_urdftool("sim", first, second, "--render", out, "--size", "64x48",
                          "--duration", "0.1", "-j", "2")
    assert result.code == 1  # the second cannot hold its bar; it still gets its pictures
    names = sorted(p.name for p in out.iterdir())
    assert names == ["first-collision.png", "first.png", "second-collision.png", "second.png"]
    for name in names:
        with Image.open(out / name) as image:
            assert image.size == (64, 48)
