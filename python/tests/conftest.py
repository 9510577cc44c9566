"""Shared fixtures: the repository's real data, the `deadreckon` binary to
compare with, and small simulated drives (seeded)."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
# The real recordings live beside the repository, as the Rust tests read them.
DATA = REPO / ".." / "shared" / "data"
COMMA2K19 = DATA / "comma2k19-rav4"


def _find_cli() -> Path:
    """The `deadreckon` binary: $DEADRECKON_BIN, else the newest built one."""
    env = os.environ.get("DEADRECKON_BIN")
    if env:
        return Path(env)
    target = Path(os.environ.get("CARGO_TARGET_DIR", REPO / "target"))
    found = [target / p / "deadreckon" for p in ("ci", "release", "debug")]
    found = [p for p in found if p.is_file()]
    if not found:
        raise RuntimeError(
            "no deadreckon binary: build it (cargo build --release) or set DEADRECKON_BIN"
        )
    return max(found, key=lambda p: p.stat().st_mtime)


@pytest.fixture(scope="session")
def cli():
    """Runs the command line; returns its standard output (fails on a non-zero exit)."""
    binary = _find_cli()

    def run(*args: str, check: bool = True) -> subprocess.CompletedProcess:
        p = subprocess.run(
            [str(binary), "--quiet", *map(str, args)], capture_output=True, text=True
        )
        if check and p.returncode != 0:
            raise AssertionError(f"deadreckon {' '.join(map(str, args))} failed:\n{p.stderr}")
        return p

    return run


@pytest.fixture(scope="session")
def cli_json(cli):
    """The parsed JSON a command prints."""

    def run(*args: str):
        return json.loads(cli(*args).stdout)

    return run


@pytest.fixture(scope="session")
def sim_drive(tmp_path_factory, cli) -> Path:
    """A short simulated calibration drive with truth (seed 3)."""
    out = tmp_path_factory.mktemp("sim") / "cal"
    cli("simulate", "--scenario", "calibration", "--seed", "3", "--duration", "240", "--out", out)
    return out


@pytest.fixture(scope="session")
def fleet_drives(tmp_path_factory, cli) -> list:
    """Four short simulated drives of different seeds, for the Dask tests."""
    base = tmp_path_factory.mktemp("fleet")
    paths = []
    for seed in range(1, 5):
        out = base / f"drive{seed}"
        cli("simulate", "--scenario", "calibration", "--seed", str(seed), "--duration", "120", "--out", out)
        paths.append(out)
    return paths


@pytest.fixture()
def drive_copy(tmp_path, sim_drive) -> Path:
    """A copy of the simulated drive that a test may damage."""
    dst = tmp_path / "drive"
    shutil.copytree(sim_drive, dst)
    return dst
