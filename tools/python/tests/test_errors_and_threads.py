# Bad input raises with the CLI's one-line message; step() lets other Python threads run.
import threading
import time

import pytest

import papertear
from conftest import SMALL


def test_bad_override_raises_value_error_with_the_cli_message():
    with pytest.raises(ValueError) as info:
        papertear.Simulation(overrides={"sheet.cells": [30, 20]})
    assert str(info.value) == ("--set sheet.cells=[30, 20]: sheet.cells: expected an array of 3 "
                               "integers, got an array of 2")
    assert isinstance(info.value, papertear.SceneError)


def test_unknown_key_names_the_nearest():
    with pytest.raises(ValueError, match=r"unknown key 'sheet.cels' \(did you mean 'sheet.cells'\?\)"):
        papertear.Simulation(overrides={"sheet.cels": [30, 20, 3]})


def test_missing_scene_file_and_bad_checkpoint(tmp_path):
    with pytest.raises(ValueError, match="no_such.toml"):
        papertear.Simulation(scene=tmp_path / "no_such.toml")
    junk = tmp_path / "junk.ptck"
    junk.write_bytes(b"not a checkpoint at all, just some bytes")
    with pytest.raises(papertear.CheckpointError, match="junk.ptck: not a papertear checkpoint"):
        papertear.Simulation.load_checkpoint(junk)


def test_step_releases_the_gil():
    sim = papertear.Simulation(overrides={"sheet.cells": [40, 40, 3]}, threads=1)
    count = [0]
    stop = threading.Event()

    def counter():
        while not stop.is_set():
            count[0] += 1

    worker = threading.Thread(target=counter)
    worker.start()
    c0 = count[0]
    time.sleep(0.2)  # the main thread waits: the counter's full speed
    rate = (count[0] - c0) / 0.2
    c1, start = count[0], time.perf_counter()
    sim.step(200)
    c2, took = count[0], time.perf_counter() - start
    stop.set()
    worker.join()
    assert took > 0.05, "the step was too short to tell"
    # Holding the GIL, step() would stall the counter for the whole step (it could run at
    # most one 5 ms switch interval); released, the counter keeps going on the other core.
    assert c2 - c1 > 0.25 * rate * took, (c2 - c1, rate, took)
