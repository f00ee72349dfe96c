"""`feelflow bench --profile`: where the gl moving tunnel's wall time goes (docs/science/performance.md)."""
import json

import pytest

from feelflow.app.cli.main import main as cli_main

pytestmark = pytest.mark.gl


def test_profile_splits_the_wall_time_of_the_moving_tunnel(tmp_path, gl_context, capsys):
    out = tmp_path / "profile.json"
    assert cli_main(["bench", "--profile", "--seconds", "0.1", "--json", str(out)]) == 0
    data = json.loads(out.read_text())
    parts = data["parts_s"]
    assert data["grid"] == "512x256" and data["steps"] >= 10 and data["mlups"] > 0
    measured = {k: v for k, v in parts.items() if not k.startswith("other")}
    # every part was entered (the body moved, each call ended with a read-back), and the parts
    # do not overlap: together they stay within the wall time
    assert len(measured) == 3 and all(v > 0 for v in measured.values())
    assert sum(measured.values()) <= data["wall_s"] * 1.01
    # the same steps without the profiler, CPU split by thread (Linux: /proc/self/task)
    threads = data["threads_without_profiler"]
    assert set(threads) == {"moving tunnel, step(10) calls", "not moved, one call"}
    for th in threads.values():
        assert th["steps"] == data["steps"] and th["llvmpipe_cpu_ms_per_step"] > 0
        assert th["other_cpu_ms_per_step"] > 0 and 0 <= th["cores_idle_fraction"] < 1
    out = capsys.readouterr().out
    assert "draw calls" in out and "llvmpipe threads" in out
