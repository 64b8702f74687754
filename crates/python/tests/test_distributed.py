"""Distributed runs on a local Ray instance: exact merges, retried failures."""

import numpy as np
import pytest

import facette

ray = pytest.importorskip("ray", reason="the distributed tests need Ray (.ci/run installs it)")
from facette import distributed  # noqa: E402


@pytest.fixture(scope="module", autouse=True)
def local_ray():
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    yield
    ray.shutdown()


def test_render_in_8_parts_equals_the_single_process_parts(tiny_scene, tmp_path):
    out = tmp_path / "dist.exr"
    img = distributed.render(tiny_scene, 8, output=out, seed=3, progress=False)
    np.testing.assert_array_equal(img, facette.render_in_parts(tiny_scene, 8, seed=3))
    np.testing.assert_array_equal(facette.read_image(out), img)


def test_a_failed_task_is_retried_and_the_result_is_identical(tiny_scene, tmp_path):
    faults = tmp_path / "faults"
    faults.mkdir()
    img = distributed.render(tiny_scene, 8, seed=3, progress=False, _fault_dir=str(faults))
    assert len(list(faults.iterdir())) == 8, "every part failed once"
    np.testing.assert_array_equal(img, facette.render_in_parts(tiny_scene, 8, seed=3))


def test_distributed_table_equals_the_single_process_table(tmp_path):
    m = '{type = "il", ni = 1.4, distribution = "beckmann", alpha = 0.5}'
    faults = tmp_path / "faults"
    faults.mkdir()
    out = tmp_path / "t.fctab"
    table = distributed.tabulate(m, 4, output=out, step=10, samples=256, progress=False, _fault_dir=str(faults))
    assert table == facette.tabulate(m, step=10, samples=256)
    assert out.read_bytes() == table
    assert len(list(faults.iterdir())) == 4
