"""Probes (app/model/probes.py): bilinear reading is exact on a linear field, pressure is the
lattice equation of state against the free stream, the series round-trip through arrays."""
from __future__ import annotations

import math

import numpy as np
import pytest

from feelflow.app.model.probes import MAX_PROBES, Probes, bilinear
from feelflow.solver.lattice import CS2


def linear_field(nx=20, ny=10):
    y, x = np.mgrid[0:ny, 0:nx].astype(float)
    rho = 1.0 + 0.001 * x - 0.002 * y
    return np.stack([rho, 0.01 * x + 0.02 * y, -0.03 * x, np.zeros_like(x)], axis=-1)


def test_bilinear_is_exact_on_a_linear_field_and_nan_outside_or_in_the_body():
    f = linear_field()
    rho, ux, uy, _ = bilinear(f, 3.25, 4.5)
    assert math.isclose(ux, 0.01 * 3.25 + 0.02 * 4.5) and math.isclose(uy, -0.03 * 3.25)
    assert math.isclose(rho, 1.0 + 0.001 * 3.25 - 0.002 * 4.5)
    assert np.isnan(bilinear(f, -1.0, 2.0)).all() and np.isnan(bilinear(f, 19.5, 2.0)).all()
    solid = np.zeros(f.shape[:2], bool)
    solid[4, 3] = True
    assert np.isnan(bilinear(f, 3.25, 4.5, solid)).all()


def test_sampling_pressure_and_the_csv_cells():
    f = linear_field()
    probes = Probes()
    probes.add(2.0, 3.0, 20, 10)
    for step in (10, 20, 20):     # a second sample at the same step is not added
        probes.sample(step, f, rho_ref=1.0)
    p = probes.items[0]
    assert p.time == [10, 20]
    assert math.isclose(p.p[0], CS2 * (1.0 + 0.002 - 0.006 - 1.0))
    assert probes.columns() == ["probe1_ux", "probe1_uy", "probe1_speed", "probe1_p"]
    cells = probes.values_at(20)
    assert math.isclose(float(cells[2]), math.hypot(float(cells[0]), float(cells[1])), rel_tol=1e-7)
    assert probes.values_at(15) == ["", "", "", ""]


def test_limits_removal_and_arrays_round_trip():
    probes = Probes()
    with pytest.raises(ValueError, match="must lie in the tunnel"):
        probes.add(30.0, 2.0, 20, 10)
    for k in range(MAX_PROBES):
        probes.add(2.0 + 3 * k, 5.0, 20, 10)
    with pytest.raises(ValueError, match=f"at most {MAX_PROBES}"):
        probes.add(1.0, 1.0, 20, 10)
    probes.sample(5, linear_field(), 1.0)
    again = Probes.from_arrays(probes.to_arrays())
    assert [(q.x, q.y, q.time, q.ux) for q in again] == [(q.x, q.y, q.time, q.ux) for q in probes]
    assert probes.remove_near(5.3, 5.2) and len(probes) == MAX_PROBES - 1
    assert not probes.remove_near(19.0, 1.0)


def test_probes_travel_in_a_session_file(tmp_path):
    """The optional probes.npz member: written with the recording, read back, checked."""
    import zipfile

    from feelflow.app.sessions import SessionError, SessionRecorder, SessionSolver, load_session
    from feelflow.solver.backend import create_solver
    from session_scenes import MODELS, drive_moving_cylinder, small_config, start_body

    cfg = small_config()
    rec = SessionRecorder(cfg, start_body(), MODELS)
    drive_moving_cylinder(SessionSolver(create_solver("numpy", cfg), rec), steps=5, extras=False)
    probes = Probes()
    probes.add(5.0, 16.0, cfg.nx, cfg.ny)
    probes.sample(3, linear_field(cfg.nx, cfg.ny), 1.0)
    rec.probes = probes.to_arrays()
    path = tmp_path / "with-probes.ffsession"
    rec.save(path)
    again = Probes.from_arrays(load_session(path).probes)
    assert [(p.x, p.y, p.time, p.ux) for p in again] == [(p.x, p.y, p.time, p.ux) for p in probes]
    rec.probes = None                      # without probes: no member, and None back
    rec.save(tmp_path / "plain.ffsession")
    assert load_session(tmp_path / "plain.ffsession").probes is None
    # a damaged member is one line
    bad = tmp_path / "bad.ffsession"
    with zipfile.ZipFile(path) as src, zipfile.ZipFile(bad, "w") as dst:
        for item in src.infolist():
            data = src.read(item)
            if item.filename == "probes.npz":
                import io

                buf = io.BytesIO()
                np.savez(buf, positions=np.array([[np.nan, 1.0]]))
                data = buf.getvalue()
            dst.writestr(item, data)
    with pytest.raises(SessionError, match="positions must be up to 4 finite"):
        load_session(bad)
