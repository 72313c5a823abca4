# Shared by the module's tests: the CLI to compare against ($PAPERTEAR, set by CTest) and a
# small scene that tears within a few hundred steps.
import os
import re
import subprocess

import pytest

SMALL = {"sheet.cells": [30, 20, 3]}


@pytest.fixture(scope="session")
def cli():
    path = os.environ.get("PAPERTEAR")
    if not path:
        pytest.skip("PAPERTEAR (the papertear CLI) is not set")
    return path


def cli_digest(cli_path, steps, threads, sets):
    """The digest `papertear run` prints for the default scene with these --set values."""
    args = [cli_path, "run", "--quiet", "--steps", str(steps), "--threads", str(threads)]
    for key, value in sets.items():
        text = "[" + ",".join(str(v) for v in value) + "]" if isinstance(value, list) else str(value)
        args += ["--set", f"{key}={text}"]
    out = subprocess.run(args, check=True, capture_output=True, text=True).stdout
    return re.search(r"^digest: ([0-9a-f]{16})$", out, re.M).group(1)
