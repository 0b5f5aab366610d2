"""``sbrdf-xr observe``: a pass from elements, a site, a window and an attitude law."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from sbrdf_xr.cli import main
from sbrdf_xr.cli.observe import attitude_of, observation_of
from sbrdf_xr.cli.parser import build_parser
from sbrdf_xr.observing.orbits import tle_checksum

WINDOW = ["--start", "2024-03-17T03:02:20", "--duration", "20", "--step", "5"]
L1 = "1 27847U 03031H   24075.50000000  .00000015  00000-0  21000-4 0  9991"
L2 = "2 27847  98.7200 129.5000 0012000  95.0000 265.0000 14.21950000109836"


def test_a_pass_from_the_command_line_writes_its_cube_and_figure(tmp_path, capsys):
    cube, fig = tmp_path / "pass.nc", tmp_path / "pass.png"
    argv = [
        "observe",
        "--elements",
        "canx1-example",
        "--site",
        "socorro-ets",
        *WINDOW,
        "--attitude",
        "spin",
        "--period",
        "90",
        "--spin-axis",
        "0.3,0.4,0.866",
        "--bands",
        "V",
        "R",
        "-o",
        str(cube),
        "--plot",
        str(fig),
        "-q",
    ]
    assert main(argv) == 0
    out = capsys.readouterr().out
    assert out.splitlines() == [f"wrote {cube}", f"wrote {fig}"]  # -q: no plan
    with xr.open_dataset(cube) as ds:
        assert ds.sizes["time"] == 5 and ds.band.values.tolist() == ["V", "R"]
        assert ds.attrs["site_name"] == "socorro-ets"
        assert ds.attrs["site_source"].startswith("Minor Planet Center")
        assert (
            ds.attrs["attitude_law"].startswith("Spin(") and "rate=4.0" in ds.attrs["attitude_law"]
        )
        assert np.all(ds.sunlit_fraction.values == 1.0) and np.all(ds.band_signal.values > 0)
    assert fig.read_bytes()[1:4] == b"PNG"


def test_an_element_file_a_site_by_coordinates_and_a_tumble(tmp_path):
    body2 = "2 00005  34.2500 100.0000 1846000 200.0000 150.0000 10.8480000000000"
    body1 = "1 00005U 58002B   24075.50000000  .00000023  00000-0  28098-4 0  999"
    other = [b + str(tle_checksum(b + "0")) for b in (body1, body2)]
    tle = tmp_path / "group.tle"
    tle.write_text(f"VANGUARD 1\n{other[0]}\n{other[1]}\nCANX-1\n{L1}\n{L2}\n")
    base = [
        "observe",
        "--elements",
        str(tle),
        "--lat",
        "33.818",
        "--lon",
        "-106.659",
        "--height",
        "1528",
        *WINDOW,
        "-o",
        str(tmp_path / "p.nc"),
    ]
    parse = build_parser().parse_args
    with pytest.raises(ValueError, match="holds 2 element sets"):
        observation_of(parse(base))
    args = parse(
        [
            *base,
            "--satellite",
            "27847",
            "--attitude",
            "tumble",
            "--omega",
            "3",
            "-2",
            "5",
            "--density",
            "1000",
        ]
    )
    from sbrdf_xr.body.spacecraft import canx1

    obs = observation_of(args, canx1())
    assert obs.orbit.name == "CANX-1" and obs.site.height == 1528.0
    assert type(obs.attitude).__name__ == "Tumble" and obs.times.size == 5
    assert np.all(obs.geometry().elevation.values > 20.0)


def test_every_attitude_law_and_its_options():
    base = [
        "observe",
        "--elements",
        "canx1-example",
        "--site",
        "socorro-ets",
        *WINDOW,
        "-o",
        "p.nc",
    ]
    parse = build_parser().parse_args
    law = attitude_of(parse([*base, "--attitude", "inertial", "--quaternion", "0", "0", "0", "1"]))
    assert type(law).__name__ == "Inertial"
    law = attitude_of(parse([*base, "--yaw", "30", "--nadir-axis=-z"]))
    assert type(law).__name__ == "Nadir" and law.yaw == 30.0
    law = attitude_of(
        parse(
            [*base, "--attitude", "sun-pointing", "--sun-axis", "+y", "--secondary-target", "north"]
        )
    )
    assert type(law).__name__ == "SunPointing" and law.secondary_target == "north"
    law = attitude_of(
        parse([*base, "--attitude", "spin", "--rate", "6", "--initial", "0,0,0.7071068,0.7071068"])
    )
    assert law.rate == 6.0
    law = attitude_of(
        parse([*base, "--attitude", "tumble", "--omega", "1", "2", "3", "--inertia", "1", "2", "3"])
    )
    assert type(law).__name__ == "Tumble"
    for extra, msg in (
        (["--attitude", "inertial"], "give --quaternion"),
        (
            ["--attitude", "spin", "--period", "-5"],
            "--period: got -5.0; allowed a finite period > 0 s",
        ),
        (["--attitude", "spin", "--period", "5", "--rate", "3"], "give --period S or --rate"),
        (["--attitude", "tumble", "--omega", "1", "2", "3"], "give --inertia"),
        (["--attitude", "series"], "give --series FILE"),
        (["--attitude", "spin", "--rate", "1", "--initial", "sideways"], "expected a quaternion"),
    ):
        with pytest.raises(ValueError, match=msg):
            attitude_of(parse([*base, *extra]))


def test_bad_windows_and_sites_are_named(tmp_path, capsys):
    out = str(tmp_path / "p.nc")
    cases = [
        (
            ["--site", "socorro-ets", "--lat", "1", "--lon", "2", *WINDOW],
            "give --site NAME or --lat/--lon/--height, not both",
        ),
        (["--lat", "1", *WINDOW], "give --site NAME .* or both --lat and --lon"),
        (
            ["--site", "socorro-ets", "--start", "2024-03-17T03:02:20"],
            r"give --stop UTC or --duration S",
        ),
        (["--site", "nowhere", *WINDOW], "nowhere"),
        (
            ["--site", "haleakala", "--start", "2024-03-17T01:20:00", "--duration", "300"],
            r"below 0 deg elevation at every time .*; it next rises above 0 deg at "
            r"2024-03-17T06:13:16 UTC \(highest 22\.0 deg at 2024-03-17T06:20:04 UTC",
        ),
    ]
    import re

    for extra, msg in cases:
        assert main(["observe", "--elements", "canx1-example", *extra, "-o", out, "-q"]) == 2
        err = capsys.readouterr().err
        assert err.startswith("sbrdf-xr: error: ") and re.search(msg, err), err
    assert not (tmp_path / "p.nc").exists()
