"""``sbrdf-xr cache info`` and ``sbrdf-xr cache prune`` on a table cache of their own."""

from __future__ import annotations

import os
import time

import pytest

from sbrdf_xr import catalog
from sbrdf_xr.cli import main
from sbrdf_xr.materials import cache, constant_material, tables


@pytest.fixture
def cache_path(tmp_path, monkeypatch):
    """A table cache holding the catalog's example-lobe (current: this installation loads
    it) and a table of another key last used 40 days ago (stale), beside a user's file."""
    d = tmp_path / "cache"
    monkeypatch.setenv("SBRDF_XR_CACHE_DIR", str(d))
    monkeypatch.setenv(cache.KEEP_DAYS_ENV, "off")
    catalog._built_material.cache_clear()
    try:
        catalog.load("example-lobe")
    finally:
        catalog._built_material.cache_clear()
    cache.cached_table(
        "old-grey",
        [],
        "()",
        lambda: constant_material(0.1, [500.0, 600.0], material="old-grey"),
        lambda t, p: tables.to_netcdf(t, p),
        tables.open_material,
        dtype="float64",
    )
    t = time.time() - 40 * 86400.0
    for p in d.glob("old-grey-*"):
        os.utime(p, (t, t))
    (d / "notes.txt").write_text("mine")
    return d


def _names(d):
    return sorted(p.name for p in d.iterdir())


def test_info_lists_the_entries_with_their_use(cache_path, capsys):
    assert main(["cache", "info"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0] == f"table cache: {cache_path}"
    assert out[1].split() == ["name", "key", "size", "last", "use", "current"]
    lobe = next(line for line in out if line.startswith("example-lobe "))
    old = next(line for line in out if line.startswith("old-grey "))
    assert lobe.endswith("yes") and "(0.0 d ago)" in lobe
    assert old.endswith("no") and "(40.0 d ago)" in old
    assert out[-2].startswith("2 entries, ") and "current for this installation: 1 (" in out[-2]
    assert out[-1] == f"pruned on every table build: off ({cache.KEEP_DAYS_ENV})"
    assert main(["cache", "info", "-q"]) == 0
    quiet = capsys.readouterr().out.splitlines()
    assert quiet == [out[0], out[-2]]


def test_prune_dry_run_then_by_age_and_staleness(cache_path, capsys):
    before = _names(cache_path)
    assert main(["cache", "prune", "--older-than", "30", "--dry-run"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert _names(cache_path) == before
    assert out[1].startswith("old-grey ") and out[-1].startswith("would remove 1 entries, ")
    assert out[-1].endswith("(a dry run: nothing removed)")
    assert main(["cache", "prune", "--older-than", "30", "-q"]) == 0
    assert capsys.readouterr().out.startswith("removed 1 entries, ")
    assert not [n for n in _names(cache_path) if n.startswith("old-grey-")]
    assert main(["cache", "prune", "--stale"]) == 0  # the catalog's table is current
    assert capsys.readouterr().out == "removed 0 entries, 0 B\n"
    assert main(["cache", "prune", "--all", "-q"]) == 0
    assert capsys.readouterr().out.startswith("removed 1 entries, ")
    assert _names(cache_path) == ["notes.txt"]  # the user's file stays


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--older-than", "-2"], "--older-than: got -2; allowed: a number of days >= 0"),
        (["--older-than", "nan"], "--older-than: got nan; allowed"),
        (["--all", "--stale"], "--all: every entry goes; give it without --older-than"),
        ([], "say which entries: --older-than DAYS, --stale or --all"),
    ],
)
def test_bad_prune_requests_say_what_is_allowed(cache_path, capsys, argv, message):
    before = _names(cache_path)
    assert main(["cache", "prune", *argv]) == 2
    assert message in capsys.readouterr().err
    assert _names(cache_path) == before


def test_a_cache_switched_off_is_said_so(monkeypatch, capsys):
    monkeypatch.setenv("SBRDF_XR_CACHE_DIR", "off")
    for argv in (["info"], ["prune", "--all"]):
        assert main(["cache", *argv]) == 2
        err = capsys.readouterr().err
        assert "table cache is switched off (SBRDF_XR_CACHE_DIR='off')" in err
