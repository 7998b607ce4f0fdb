"""``python -m post plot-deformed`` writes PNGs (smoke tests) and its
sampling helpers keep element boundaries."""

from __future__ import annotations

import shutil
from pathlib import Path

import h5py
import numpy as np
import pytest

from post.__main__ import main
from post.plot import breakpoints, deformed_grid, sample_parameters
from post.reader import body_displacement, read_result

from .conftest import exact_stretch

PNG = b"\x89PNG\r\n\x1a\n"


def _is_png(path: Path) -> bool:
    return path.is_file() and path.read_bytes()[:8] == PNG and path.stat().st_size > 20_000


def test_plot_deformed_default_name(stretch_h5: Path, tmp_path: Path,
                                    capsys: pytest.CaptureFixture[str]) -> None:
    result = tmp_path / "stretch.h5"
    shutil.copy(stretch_h5, result)
    assert main(["plot-deformed", str(result)]) == 0
    out = tmp_path / "stretch-deformed-000002.png"
    assert capsys.readouterr().out.strip() == str(out) and _is_png(out)


def test_plot_deformed_options(two_h5: Path, tmp_path: Path) -> None:
    for args in (["--step", "1", "--scale", "5"], ["--step", "-2", "--reference"],
                 ["--step", "0"]):
        out = tmp_path / f"two{'_'.join(args)}.png"
        assert main(["plot-deformed", str(two_h5), "-o", str(out), *args]) == 0, args
        assert _is_png(out), args


def test_plot_failed_run(crush_h5: Path, tmp_path: Path) -> None:
    out = tmp_path / "crush.png"
    assert main(["plot-deformed", str(crush_h5), "-o", str(out)]) == 0
    assert _is_png(out)


def test_plot_without_steps(two_h5: Path, tmp_path: Path,
                            capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "empty.h5"
    shutil.copy(two_h5, path)
    with h5py.File(path, "r+") as f:
        f.attrs["status"] = np.bytes_(b"running")
        for key in list(f["steps"]):
            del f["steps"][key]
    assert main(["plot-deformed", str(path), "-o", str(tmp_path / "a.png")]) == 1
    assert "no converged step" in capsys.readouterr().err
    assert main(["plot-deformed", str(path), "-o", str(tmp_path / "b.png"), "--step", "0"]) == 0
    assert main(["plot-deformed", str(two_h5), "-o", str(tmp_path / "c.png"), "--step", "7"]) == 1


def test_sampling_contains_breakpoints() -> None:
    br = np.array([0.0, 0.1, 0.5, 1.0])
    t = sample_parameters(br, minimum=30)
    assert np.all(np.isin(br, t)) and np.all(np.diff(t) > 0) and len(t) >= 30
    assert t[0] == 0.0 and t[-1] == 1.0


def test_deformed_grid(stretch_h5: Path) -> None:
    r = read_result(stretch_h5)
    body = r.bodies["slab"]
    bx, be = breakpoints(body)
    np.testing.assert_allclose(bx, np.linspace(0, 1, 9), atol=1e-15)
    np.testing.assert_allclose(be, [0, 0.5, 1], atol=1e-15)
    u = body_displacement(r, "slab")
    pts, mag = deformed_grid(body, u, scale=3.0, minimum=40)
    ref, _ = deformed_grid(body, u, scale=0.0, minimum=40)
    exact = exact_stretch(ref, r.steps[-1].time)
    assert np.abs(pts - ref - 3.0 * exact).max() < 1e-12
    assert np.abs(mag - np.linalg.norm(exact, axis=-1)).max() < 1e-12


def test_stress_field_of_the_stretch(fields_h5: Path, tmp_path: Path,
                                     capsys: pytest.CaptureFixture[str]) -> None:
    """The slab stretch is uniform: sigma_xx = E eps / (1 - nu^2), sigma_yy = 0 (plane
    strain, free sides). `plot-deformed --field` colours by it (issue 38, item 3: no
    figure showed stress); the interpolation between samples returns the solver's
    values at its sample points and the uniform value everywhere."""
    from post.plot import deformed_figure
    from post.quantity import sampled_quantity

    result = read_result(fields_h5)
    step = result.steps[-1]
    slab = result.bodies["slab"]
    rng = np.random.default_rng(1)
    xi, eta = rng.random(200), rng.random(200)
    sxx = sampled_quantity(step, slab, "stress_xx", xi, eta)
    np.testing.assert_allclose(sxx, 0.01 / (1 - 0.3 ** 2), rtol=1e-9)
    np.testing.assert_allclose(sampled_quantity(step, slab, "stress_yy", xi, eta), 0.0, atol=1e-10)
    # at the samples (element centres: no neighbour shares them) the stored values
    f = step.fields["slab"]
    centre = np.arange(len(f["xi"])) % 9 == 4
    np.testing.assert_array_equal(sampled_quantity(step, slab, "von_mises", f["xi"][centre], f["eta"][centre]),
                                  f["von_mises"][centre])
    out = tmp_path / "fields.h5"
    shutil.copy(fields_h5, out)
    assert main(["plot-deformed", str(out), "--field", "von_mises"]) == 0
    png = tmp_path / "fields-von_mises-000002.png"
    assert capsys.readouterr().out.strip() == str(png) and _is_png(png)
    fig, meshes = deformed_figure(result, field="stress_xx")
    (mesh,) = meshes.values()
    assert "Cauchy stress sigma_xx [" in fig.axes[-1].get_ylabel()
    np.testing.assert_allclose(mesh.get_array(), 0.01 / 0.91, rtol=1e-9)


def test_field_without_samples_or_unknown(stretch_h5: Path, tmp_path: Path,
                                          capsys: pytest.CaptureFixture[str]) -> None:
    """A step without sampled fields names the remedy; an unknown name lists the known."""
    assert main(["plot-deformed", str(stretch_h5), "--field", "von_mises", "-o", str(tmp_path / "a.png")]) == 2
    err = capsys.readouterr().err
    assert "step 2 has no sampled fields" in err and "[output] to the spec, or &output to the case" in err
    assert main(["plot-deformed", str(stretch_h5), "--field", "tresca", "-o", str(tmp_path / "b.png")]) == 2
    assert "--field 'tresca': not a quantity (known: u, ux, uy, von_mises, stress_xx" in capsys.readouterr().err
    assert not list(tmp_path.glob("*.png"))


def test_colour_scale_per_body(two_h5: Path) -> None:
    """Each body its own colour range (the die's rigid shift does not flatten the
    slab's colours, issue 38, item 3), or one shared range."""
    from post.plot import deformed_figure

    result = read_result(two_h5)
    fig, meshes = deformed_figure(result)
    ranges = {name: (m.norm.vmin, m.norm.vmax) for name, m in meshes.items()}
    for name, mesh in meshes.items():
        values = np.asarray(mesh.get_array())
        assert ranges[name] == (0.0, pytest.approx(values.max(), rel=1e-12)), name
    assert ranges["die"][1] > 1.2 * ranges["slab"][1]
    assert len([a for a in fig.axes if a.get_label() == "<colorbar>"]) == 2
    fig, meshes = deformed_figure(result, colour_scale="shared")
    assert {(m.norm.vmin, m.norm.vmax) for m in meshes.values()} == {(0.0, ranges["die"][1])}


def test_rigid_master_moves_with_the_magnification(line_h5: Path) -> None:
    """Bodies drawn at x 20: the rigid line is drawn where its motion x 20 puts it, on
    the magnified dent (it was drawn at its true position, 0.19 above it)."""
    from post.plot import deformed_figure

    result = read_result(line_h5)
    c = result.steps[-1].contact[0]
    assert np.allclose(c.rigid_offset, [0.0, -0.01])
    fig, meshes = deformed_figure(result, scale=20.0, zoom=False)
    (line,) = [ln for ln in fig.axes[0].get_lines() if ln.get_label().startswith("rigid master of slab")]
    np.testing.assert_allclose(line.get_ydata(), -0.2, atol=1e-12)
    assert "(its motion x 20, as the bodies)" in line.get_label()
    # the slab's top under the line, drawn at x 20, is within the penetration x 20 of it
    top = meshes["slab"].get_coordinates()[-1, :, 1]
    assert abs(top.min() - (-0.2)) < 20 * float(-np.nanmin(c.gap)) + 1e-9
