"""`msdlab run SCENE --sweep`: one table of outcomes, checked against the stability limit of
velocity Verlet for a mass on a spring: bounded iff ω·dt < 2, with ω = √(k/m)."""

from __future__ import annotations

import csv
import math
from pathlib import Path

import pytest

from msdlab.cli import main
from msdlab.scenes import get_scene
from msdlab.scenes.sweep import parse_sweeps

STIFFNESSES = (0.25, 1.0, 4.0)  # unit mass: ω = 0.5, 1, 2 per frame
STEPS = (0.9, 1.1, 1.9, 2.1, 3.9, 4.1)  # frames; none within 5 % of a limit 2/ω = 4, 2, 1


def test_the_sweep_table_finds_the_verlet_stability_limit(tmp_path: Path) -> None:
    out = tmp_path / "sweep.csv"
    status = main([
        "run", "hanging-particle", "--set", "damping=1.0", "--duration", "400", "--out", str(out),
        "--sweep", "stiffness=" + ",".join(map(str, STIFFNESSES)),
        "--sweep", "dt=" + ",".join(map(str, STEPS)),
    ])  # fmt: skip
    assert status == 0
    rows = list(csv.DictReader(out.open()))
    assert [(float(r["stiffness"]), float(r["dt"])) for r in rows] == [
        (k, dt) for k in STIFFNESSES for dt in STEPS
    ]
    for row in rows:
        omega_dt = math.sqrt(float(row["stiffness"])) * float(row["dt"])
        assert (row["diverged"] == "True") == (omega_dt > 2), row
        if row["diverged"] == "False":  # the whole run, the spring's stretch g/k each way
            assert float(row["time"]) == pytest.approx(400, abs=float(row["dt"]))
            amplitude = 2 * 0.5 / float(row["stiffness"])
            assert float(row["max_displacement"]) == pytest.approx(amplitude, rel=0.05)


def test_sweeping_what_the_scene_does_not_have_names_the_valid_settings() -> None:
    scene = get_scene("hanging-particle")
    with pytest.raises(ValueError, match="valid: stiffness, gravity"):
        parse_sweeps(scene, ["mass=1,2"])
    with pytest.raises(ValueError, match="key=v1,v2"):
        parse_sweeps(scene, ["dt"])
    with pytest.raises(ValueError, match="twice"):
        parse_sweeps(scene, ["dt=1", "dt=2"])
    assert main(["run", "hanging-particle", "--cluster", "local:2"]) == 2


@pytest.mark.parametrize("where", ["local:2", "scheduler"])
def test_a_sweep_on_a_cluster_writes_the_same_table(tmp_path: Path, where: str, request) -> None:
    spec = request.getfixturevalue("scheduler") if where == "scheduler" else where
    command = ["run", "hanging-particle", "--duration", "100", "--sweep", "dt=1.5,2.5"]
    assert main([*command, "--out", str(tmp_path / "local.csv")]) == 0
    assert main([*command, "--out", str(tmp_path / "cluster.csv"), "--cluster", spec]) == 0
    assert (tmp_path / "cluster.csv").read_text() == (tmp_path / "local.csv").read_text()


def test_without_out_the_table_goes_to_the_ignored_output_folder(tmp_path, monkeypatch):
    """msdlab-output/, which the course's and the release's .gitignore ignore: a sweep run in
    a clone leaves git's view of it as it was."""
    monkeypatch.chdir(tmp_path)
    status = main(["run", "hanging-particle", "--duration", "2", "--sweep", "dt=0.5,1"])
    assert status == 0
    assert [p.relative_to(tmp_path).as_posix() for p in tmp_path.rglob("*") if p.is_file()] == [
        "msdlab-output/hanging-particle-sweep.csv"
    ]
