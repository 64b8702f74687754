import os
import pathlib
import shutil
import subprocess

import pytest

REPO = pathlib.Path(__file__).resolve().parents[3]


@pytest.fixture(scope="session")
def facette_bin():
    """The `facette` binary of this checkout, as the README's test command builds it
    (`cargo test --workspace --profile optimized-tests`), in CARGO_TARGET_DIR where that is
    set; FACETTE_BIN names another."""
    target = pathlib.Path(os.environ.get("CARGO_TARGET_DIR") or REPO / "target")
    path = os.environ.get("FACETTE_BIN") or str(target / "optimized-tests" / "facette")
    if not os.path.exists(path):
        subprocess.run(
            ["cargo", "build", "--profile", "optimized-tests", "-p", "facette"],
            cwd=REPO,
            check=True,
        )
    return path


@pytest.fixture
def tiny_scene(tmp_path):
    text = """
[camera]
position = [0, 0, 4]
target = [0, 0, 0]
fov = 40

[film]
width = 24
height = 16
spp = 8

[[objects]]
shape = "sphere"
radius = 1
material = { type = "il", kd = [0.8, 0.4, 0.2], ni = 1.5, alpha = 0.3 }

[[lights]]
type = "point"
position = [2, 2, 3]
intensity = 10

[[lights]]
type = "constant"
radiance = 0.5
"""
    path = tmp_path / "tiny.toml"
    path.write_text(text)
    return path
