"""Output targets are checked before any work: ``-o -`` is refused (outputs are files),
and a target whose directory cannot be written is refused at once, not after the run."""

from __future__ import annotations

import pytest

from sbrdf_xr.cli import main


@pytest.mark.parametrize(
    "argv",
    [
        ["simulate", "canx1-rotation", "-o", "-"],
        ["simulate", "canx1-rotation", "-o", "{tmp}/c.nc", "--plot", "-"],
        ["photometry", "{tmp}/no-cube.nc", "-o", "-"],
    ],
)
def test_dash_is_refused_as_an_output(tmp_path, capsys, argv):
    status = main([a.format(tmp=tmp_path) for a in argv])
    err = capsys.readouterr().err
    assert status == 2 and "'-' names no file" in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "-").exists() and not (tmp_path / "c.nc").exists()


@pytest.mark.parametrize("target", ["afile/figures/c.png", "/proc/c.png"])
def test_a_plot_target_that_cannot_be_written_is_refused_before_the_run(
    tmp_path, capsys, monkeypatch, target
):
    import sbrdf_xr.engine.run as run

    def never(*args, **kwargs):  # the simulation must not start
        raise AssertionError("the cube was simulated before the plot target was checked")

    monkeypatch.setattr(run, "simulate", never)  # imported by the command when it runs
    monkeypatch.chdir(tmp_path)
    (tmp_path / "afile").write_text("a file where a directory goes")
    status = main(["simulate", "canx1-rotation", "-o", "c.nc", "--plot", target])
    err = capsys.readouterr().err
    assert status == 2 and "cannot write" in err and target in err, err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["afile"]
