# The module builds and steps a scene exactly as `papertear run` does: equal digests on every
# thread count, and a checkpoint continues bit for bit.
import pytest

import papertear
from conftest import SMALL, cli_digest

STEPS = 150


@pytest.mark.parametrize("threads", [1, 2, 3])
def test_digest_equals_cli(cli, threads):
    sim = papertear.Simulation(scene=None, overrides=SMALL, threads=threads)
    sim.step(STEPS)
    assert sim.threads == threads
    assert sim.steps_done == STEPS
    assert sim.digest() == cli_digest(cli, STEPS, threads, SMALL)


def test_digest_of_a_scene_file_equals_cli(cli, tmp_path):
    scene = tmp_path / "pull.toml"
    scene.write_text('[sheet]\ncells = [24, 16, 2]\n[material]\npreset = "washi"\n')
    sim = papertear.Simulation(scene=str(scene), threads=2)
    sim.step(80)
    import subprocess, re
    out = subprocess.run([cli, "run", str(scene), "--quiet", "--steps", "80", "--threads", "1"],
                         check=True, capture_output=True, text=True).stdout
    assert sim.digest() == re.search(r"^digest: (\w+)$", out, re.M).group(1)


def test_steps_in_pieces_equal_one_call():
    one = papertear.Simulation(overrides=SMALL, threads=2)
    one.step(120)
    parts = papertear.Simulation(overrides=SMALL, threads=1)
    for n in (1, 39, 80):
        parts.step(n)
    assert parts.digest() == one.digest()


def test_checkpoint_continues_bit_for_bit(tmp_path):
    straight = papertear.Simulation(overrides=SMALL, threads=2)
    straight.step(200)
    first = papertear.Simulation(overrides=SMALL, threads=2)
    first.step(100)
    path = tmp_path / "half.ptck"
    first.save_checkpoint(path)
    resumed = papertear.Simulation.load_checkpoint(path, threads=3)
    assert resumed.steps_done == 100 and resumed.digest() == first.digest()
    resumed.step(100)
    assert resumed.digest() == straight.digest()


def test_two_simulations_are_independent():
    a = papertear.Simulation(overrides=SMALL, threads=1)
    b = papertear.Simulation(overrides={"sheet.cells": [12, 12, 2]}, threads=2)
    a.step(50)
    alone = papertear.Simulation(overrides=SMALL, threads=1)
    alone.step(50)
    assert a.digest() == alone.digest()
    assert b.steps_done == 0 and b.cells == (12, 12, 2)
