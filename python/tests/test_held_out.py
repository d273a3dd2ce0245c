"""The held-out experiments on real data (needs FUZZYVOX_DATA): ``fuzzyvox.rgbd`` and
``fuzzyvox.mono`` return the keys the command's ``--json`` prints, for the same settings."""

import json
import subprocess
from pathlib import Path

import pytest

import fuzzyvox

from conftest import data_file

#: The command, built by ``cargo build --release --bin fuzzyvox`` (CI builds it before pytest).
BINARY = Path(__file__).resolve().parents[2] / "target" / "release" / "fuzzyvox"

#: Cheap settings: every 8th pixel checked, coarse voxels.
SETTINGS = {"res": 0.1, "pixel_step": 8}


def few_frames(tmp_path: Path, count: int, sequence: str = "rgbd-7scenes-redkitchen") -> Path:
    """The first `count` frames of a shared sequence, linked into a folder of their own."""
    source = data_file(f"{sequence}/camera-intrinsics.txt").parent
    folder = tmp_path / "frames"
    folder.mkdir()
    numbers = sorted({p.name.split(".")[0] for p in source.glob("frame-*")})[:count]
    for path in sorted(source.iterdir()):
        if not path.name.startswith("frame-") or path.name.split(".")[0] in numbers:
            (folder / path.name).symlink_to(path)
    return folder


def command_json(command: str, folder: Path, *extra: str) -> dict:
    """`fuzzyvox COMMAND --dir FOLDER ... --json` with the same settings (and `extra`)."""
    if not BINARY.is_file():
        pytest.fail(f"{BINARY} is missing: build it with `cargo build --release --bin fuzzyvox`")
    args = [str(BINARY), command, "--dir", str(folder), "--json"]
    for key, value in SETTINGS.items():
        args += ["--" + key.replace("_", "-"), str(value)]
    args += extra
    done = subprocess.run(args, capture_output=True, text=True, check=True)
    return json.loads(done.stdout)


def key_tree(value):
    """The keys of a JSON value, recursively (lists by element)."""
    if isinstance(value, dict):
        return {k: key_tree(v) for k, v in value.items()}
    if isinstance(value, list):
        return [key_tree(v) for v in value]
    return None


def test_rgbd_report_has_the_commands_keys(tmp_path):
    folder = few_frames(tmp_path, 15)
    report = fuzzyvox.rgbd(folder, **SETTINGS)
    assert key_tree(report) == key_tree(command_json("rgbd", folder))
    assert [m["model"] for m in report["maps"]] == ["logodds", "alpha", "fuzzy"]
    assert [m["operator"] for m in report["maps"]] == [None, None, "product"]
    assert report["frames"] == 15 and report["held_out_frames"] == 3
    assert 0.0 < report["maps"][2]["within_2_voxels"] <= 1.0


def test_mono_report_has_the_commands_keys(tmp_path):
    folder = few_frames(tmp_path, 10)
    report = fuzzyvox.mono(folder, **SETTINGS)
    assert key_tree(report) == key_tree(command_json("mono", folder))
    assert report["depth_range"] == [0.3, 8.0]
    assert set(report["seconds"]) == {"read", "depth", "integrate", "check"}
    assert "plan_queries" not in report["maps"][0]


def test_mono_flights_have_the_commands_keys_and_figures(tmp_path):
    # Half the HoloLens walk: room enough near the camera path for start/goal pairs.
    folder = few_frames(tmp_path, 40, "rgbd-hololens-000")
    report = fuzzyvox.mono(folder, **SETTINGS, plan=3, seed=2)
    command = command_json("mono", folder, "--plan", "3", "--seed", "2")
    assert key_tree(report) == key_tree(command)
    for ours, theirs in zip(report["maps"], command["maps"]):
        assert 0 < ours["plan_queries"] <= 3
        for key in ["plan_queries", "plan_success", "plan_collisions", "reference_plan_success"]:
            assert ours[key] == theirs[key], key


def test_mono_consistency_options_match_the_command(tmp_path):
    folder = few_frames(tmp_path, 16, "rgbd-hololens-000")
    report = fuzzyvox.mono(folder, **SETTINGS, consistency=2, min_agreeing=1)
    command = command_json("mono", folder, "--consistency", "2", "--min-agreeing", "1")
    assert report["consistency"] == command["consistency"]
    check = report["consistency"]
    assert (check["neighbours"], check["min_agreeing"]) == (2, 1)
    assert 0 < check["pixels_kept"] <= check["pixels_checked"]
    # Without the check every pixel of the depth stage reaches the maps.
    unchecked = fuzzyvox.mono(folder, **SETTINGS, consistency=0)
    assert unchecked["consistency"]["pixels_checked"] == 0
    assert unchecked["depth_stage"]["pixels"] > report["depth_stage"]["pixels"]
    with pytest.raises(fuzzyvox.InvalidInputError, match="min_agreeing"):
        fuzzyvox.mono(folder, 0.1, consistency=2, min_agreeing=5)


def test_held_out_runs_refuse_bad_settings(tmp_path):
    folder = few_frames(tmp_path, 10)
    with pytest.raises(fuzzyvox.InvalidInputError, match="holdout"):
        fuzzyvox.rgbd(folder, 0.1, holdout=1)
    with pytest.raises(fuzzyvox.InvalidInputError, match="map model"):
        fuzzyvox.rgbd(folder, 0.1, model="octree")
    with pytest.raises(fuzzyvox.InvalidInputError, match="fuzzy model only"):
        fuzzyvox.rgbd(folder, 0.1, model="logodds", op="max")
    with pytest.raises(fuzzyvox.InvalidInputError, match="near < far"):
        fuzzyvox.mono(folder, 0.1, near=5.0, far=2.0)
    report = fuzzyvox.rgbd(folder, 0.1, model="fuzzy", pixel_step=16, save=tmp_path / "maps")
    assert [m["model"] for m in report["maps"]] == ["fuzzy"]
    assert fuzzyvox.load(tmp_path / "maps" / "fuzzy.fvx").kind == "fuzzy"


def test_held_out_options_are_checked_before_any_work(tmp_path):
    missing = tmp_path / "no-such-folder"
    with pytest.raises(TypeError, match="unexpected keyword argument 'pixelstep'"):
        fuzzyvox.rgbd(missing, 0.1, pixelstep=8)
    with pytest.raises(TypeError, match="unexpected keyword argument 'save'"):
        fuzzyvox.mono(missing, 0.1, save=tmp_path)
    with pytest.raises(TypeError, match="holdout"):
        fuzzyvox.rgbd(missing, 0.1, holdout="five")
    with pytest.raises(fuzzyvox.MapFileError):
        fuzzyvox.rgbd(missing, 0.1, holdout=5)
