"""Factories of small labelled objects for tests, notebooks and benchmarks.

Importable as ``sbrdf_xr.testing`` so that every user of the package can build the
same tiny materials, measurement sets and spacecraft the test-suite uses.
"""

from __future__ import annotations

import itertools

import numpy as np
import xarray as xr

# ----------------------------------------------------------------- materials


def lobe_function(
    wavelength: np.ndarray,
    *,
    diffuse: float = 0.02,
    peak: float = 2.0,
    width: float = 6.0,
):
    """A smooth analytic sBRDF: a diffuse floor plus a Gaussian specular lobe.

    ``f = diffuse * s(lambda) + peak * s(lambda) * exp(-(dt**2 + phi**2) / (2 w(ti)**2))``
    with ``w(ti) = width * (1 + ti/90)`` [degree] and a gentle spectral slope
    ``s(lambda)`` (0.8-1.2 over 400-1100 nm).  Not a physical model: a
    ground truth with known structure for tests of the table machinery.

    Parameters
    ----------
    wavelength : ndarray
        Wavelengths [nm].
    diffuse, peak : float
        Diffuse and peak sBRDF [sr-1].
    width : float
        Lobe standard deviation at normal incidence [degree].

    Returns
    -------
    callable
        ``func(theta_i, delta_theta, phi) -> (n, n_wavelength)`` [sr-1].

    Examples
    --------
    On the lobe's axis the sBRDF is ``(diffuse + peak) * s(lambda)``, 1.616 at 400 nm
    (``s = 0.8``):

    >>> import numpy as np
    >>> from sbrdf_xr.testing import lobe_function
    >>> f = lobe_function(np.array([400.0, 750.0, 1100.0]))
    >>> f([10.0], [0.0], [0.0]).round(6).tolist()
    [[1.616, 2.02, 2.424]]
    >>> f([10.0], [30.0], [0.0]).round(6).tolist()  # 30 deg off the lobe: the floor
    [[0.016064, 0.02008, 0.024096]]
    """
    wl = np.asarray(wavelength, dtype=np.float64)
    s = 0.8 + 0.4 * (wl - 400.0) / 700.0

    def func(ti: np.ndarray, dt: np.ndarray, ph: np.ndarray) -> np.ndarray:
        ti, dt, ph = (np.asarray(a, dtype=np.float64)[..., None] for a in (ti, dt, ph))
        w = width * (1.0 + ti / 90.0)
        return diffuse * s + peak * s * np.exp(-(dt**2 + ph**2) / (2.0 * w**2))

    return func


def make_measurements(
    n_wavelength: int = 31,
    theta_i: tuple[float, ...] = (10.0, 25.0, 40.0, 55.0, 70.0),
    noise: float = 0.0,
    **kwargs: float,
) -> xr.Dataset:
    """A small measurement set of :func:`lobe_function` on the paper-000 scheme.

    Parameters
    ----------
    n_wavelength : int
        Number of wavelengths between 400 and 1100 nm.
    theta_i : tuple of float
        Incidence angles [degree].
    noise : float
        Relative noise [1].
    **kwargs
        Passed to :func:`lobe_function`.

    Returns
    -------
    xarray.Dataset

    Examples
    --------
    >>> from sbrdf_xr.testing import make_measurements
    >>> ds = make_measurements(n_wavelength=5)
    >>> dict(ds.sizes), ds.attrs["material"]
    ({'sample': 150, 'wavelength': 5}, 'test-lobe')
    >>> sorted(set(ds.theta_i.values.tolist()))
    [10.0, 25.0, 40.0, 55.0, 70.0]
    """
    from .materials.goniometer import measure

    wl = np.linspace(400.0, 1100.0, n_wavelength)
    return measure(
        lobe_function(wl, **kwargs),
        wl,
        theta_i,
        noise=noise,
        noise_floor=0.05,
        material="test-lobe",
        provenance="sbrdf_xr.testing.lobe_function",
    )


def make_material(
    n_wavelength: int = 11,
    *,
    value: float | None = None,
    theta_i: np.ndarray | None = None,
    delta_theta: np.ndarray | None = None,
    phi: np.ndarray | None = None,
    dtype: type = np.float64,
) -> xr.DataArray:
    """A small material table: constant ``value`` or :func:`lobe_function` on a grid.

    Parameters
    ----------
    n_wavelength : int
        Wavelengths between 400 and 1100 nm.
    value : float, optional
        Constant sBRDF [sr-1] everywhere (a Lambertian table when the grid spans
        the hemisphere); default the lobe function.
    theta_i, delta_theta, phi : ndarray, optional
        Grids [degree]; defaults 0-90 step 10, -60..40 step 10, 0..30 step 5.
    dtype : numpy dtype
        dtype of the values.

    Returns
    -------
    xarray.DataArray

    Examples
    --------
    >>> from sbrdf_xr.testing import make_material
    >>> lobe = make_material(5)
    >>> lobe.dims, lobe.shape
    (('theta_i', 'delta_theta', 'phi', 'wavelength'), (10, 11, 7, 5))
    >>> float(make_material(3, value=0.2).max())
    0.2
    """
    from .materials.tables import new_material

    wl = np.linspace(400.0, 1100.0, n_wavelength)
    ti = np.arange(0.0, 91.0, 10.0) if theta_i is None else np.asarray(theta_i, float)
    dt = np.arange(-60.0, 41.0, 10.0) if delta_theta is None else np.asarray(delta_theta, float)
    ph = np.arange(0.0, 31.0, 5.0) if phi is None else np.asarray(phi, float)
    if value is None:
        g = np.meshgrid(ti, dt, ph, indexing="ij")
        vals = lobe_function(wl)(*(a.ravel() for a in g)).reshape(ti.size, dt.size, ph.size, -1)
    else:
        vals = np.full((ti.size, dt.size, ph.size, wl.size), value)
    return new_material(
        vals.astype(dtype),
        ti,
        dt,
        ph,
        wl,
        material="test-material",
        source="synthetic",
        provenance="sbrdf_xr.testing.make_material",
    )


#: Gauss-Legendre order of :func:`reference_reflectance` on every interval.
REFERENCE_ORDER = 8


def _reference_breaks(lo: float, hi: float, centre: float, fine: float) -> np.ndarray:
    """Interval ends on ``[lo, hi]``, geometrically graded (ratio 2) away from
    ``centre``: ``fine`` wide next to it, at most 10 degree wide far from it."""
    steps = fine * 2.0 ** np.arange(40)
    steps = steps[steps < 2 * (hi - lo)]
    pts = np.concatenate([[lo, hi], centre + steps, centre - steps, [centre]])
    pts = np.unique(pts[(pts >= lo) & (pts <= hi)])
    out = [pts[:1]]
    for a, b in itertools.pairwise(pts):  # no piece wider than 10 degree
        out.append(np.linspace(a, b, int(np.ceil((b - a) / 10.0)) + 1)[1:])
    return np.concatenate(out)


def reference_reflectance(
    func, theta_i: np.ndarray, *, fine: float = 0.1, order: int = REFERENCE_ORDER
) -> np.ndarray:
    """Directional-hemispherical reflectance of an sBRDF function, by direct quadrature.

    ``rho(theta_i) = 2 int_0^90 int_-90^90 f(theta_i, t - theta_i, phi) cos(phi)**2
    cos(t) dt dphi`` (paper 001 Eq. 1 in the coordinates of paper 000 Fig. 4, where
    ``d omega = cos(phi) dphi dt`` and ``cos theta_r = cos(phi) cos(t)``), with
    ``order``-point Gauss-Legendre rules on intervals graded geometrically away from
    the specular direction (``t = theta_i``, ``phi = 0``): ``fine`` degree next to it,
    doubling per interval to at most 10 degree.  The function is evaluated only
    strictly inside the hemisphere, so it resolves a needle lobe (GGX roughness 0.03)
    and its long tails without knowing the model; a reference for look-up tables
    that is independent of any table grid.

    Parameters
    ----------
    func : callable
        ``func(theta_i, delta_theta, phi) -> (n, n_wavelength)`` sBRDF [sr-1] for 1-D
        angle arrays [degree] (:func:`sbrdf_xr.materials.models.spectrum_function`,
        :func:`lobe_function`).
    theta_i : array_like
        Incidence angles [degree], ``0 <= theta_i < 90``.
    fine : float, default 0.1
        Width of the intervals next to the specular direction [degree].
    order : int, default 8
        Gauss-Legendre points per interval and axis.

    Returns
    -------
    ndarray, shape (n_theta_i, n_wavelength)
        Reflectance [1].

    Examples
    --------
    >>> wl = np.array([500.0, 900.0])
    >>> lambert = lambda ti, dt, ph: np.full((np.size(ti), wl.size), 0.5 / np.pi)
    >>> np.round(reference_reflectance(lambert, [0.0, 60.0]), 9)
    array([[0.5, 0.5],
           [0.5, 0.5]])
    """
    x, w = np.polynomial.legendre.leggauss(order)
    out = []
    for ti in np.atleast_1d(np.asarray(theta_i, dtype=np.float64)):
        tb = _reference_breaks(-90.0, 90.0, ti, fine)
        pb = _reference_breaks(0.0, 90.0, 0.0, fine)
        tn = (0.5 * np.diff(tb)[:, None] * x + 0.5 * (tb[:-1] + tb[1:])[:, None]).ravel()
        tw = (0.5 * np.diff(tb)[:, None] * w).ravel()
        pn = (0.5 * np.diff(pb)[:, None] * x + 0.5 * (pb[:-1] + pb[1:])[:, None]).ravel()
        pw = (0.5 * np.diff(pb)[:, None] * w).ravel()
        acc = 0.0
        for j in range(0, pn.size, 64):  # in slices of phi, to bound the memory
            p = pn[j : j + 64]
            tt, pp = np.meshgrid(tn, p, indexing="ij")
            ww = np.outer(tw, pw[j : j + 64]) * np.cos(np.radians(pp)) ** 2
            ww *= np.cos(np.radians(tt))
            f = np.asarray(func(np.full(tt.size, ti), (tt - ti).ravel(), pp.ravel()))
            acc = acc + ww.ravel() @ f
        out.append(2.0 * np.radians(1.0) ** 2 * acc)
    return np.array(out)


# ---------------------------------------------------------------- spacecraft
# (section owned by the spacecraft/visibility issue: cube, L-shaped body, plate with a fin)

#: Material of the test spacecraft built below.
TEST_SPACECRAFT_MATERIAL = "white-paint-a276"


def _ear_clip(polygon: np.ndarray) -> np.ndarray:
    """Triangles (index triples, counter-clockwise) of a simple counter-clockwise polygon."""
    idx = list(range(len(polygon)))
    tris: list[tuple[int, ...]] = []

    def cross(o, a, b):
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    while len(idx) > 3:
        for k in range(len(idx)):
            i0, i1, i2 = idx[k - 1], idx[k], idx[(k + 1) % len(idx)]
            a, b, c = polygon[i0], polygon[i1], polygon[i2]
            if cross(a, b, c) <= 0:
                continue  # reflex or collinear corner
            inside = any(
                cross(a, b, polygon[j]) >= 0
                and cross(b, c, polygon[j]) >= 0
                and cross(c, a, polygon[j]) >= 0
                for j in idx
                if j not in (i0, i1, i2)
            )
            if not inside:
                tris.append((i0, i1, i2))
                idx.pop(k)
                break
        else:  # pragma: no cover - not a simple polygon
            raise ValueError("polygon is not simple and counter-clockwise")
    tris.append(tuple(idx))
    return np.array(tris)


def prism_mesh(polygon_xy, z0: float, z1: float):
    """Closed, outward-wound prism: a simple counter-clockwise polygon in xy extruded along z.

    Parameters
    ----------
    polygon_xy : array_like, shape (n, 2)
        Vertices of the cross-section [m], counter-clockwise, without repeating the first.
    z0, z1 : float
        Bottom and top of the prism [m].

    Returns
    -------
    trimesh.Trimesh
        ``4 n - 4`` facets: two per side wall, ``n - 2`` per cap.

    Examples
    --------
    A unit square extruded over 2 m: 12 facets enclosing 2 m3.

    >>> from sbrdf_xr.testing import prism_mesh
    >>> mesh = prism_mesh([(0, 0), (1, 0), (1, 1), (0, 1)], 0.0, 2.0)
    >>> len(mesh.faces), bool(mesh.is_watertight), round(float(mesh.volume), 6)
    (12, True, 2.0)
    """
    import trimesh

    p = np.asarray(polygon_xy, dtype=float)
    n = len(p)
    vertices = np.vstack(
        [np.column_stack([p, np.full(n, z0)]), np.column_stack([p, np.full(n, z1)])]
    )
    cap = _ear_clip(p)
    faces = [cap[:, ::-1], cap + n]  # bottom faces -z, top faces +z
    i = np.arange(n)
    j = (i + 1) % n
    faces.append(np.column_stack([i, j, j + n]))
    faces.append(np.column_stack([i, j + n, i + n]))
    return trimesh.Trimesh(vertices, np.vstack(faces), process=False)


def _as_spacecraft(mesh, name: str):
    from .body.spacecraft import load_spacecraft

    mesh.visual.face_colors = np.tile([200, 200, 200, 255], (len(mesh.faces), 1))
    return load_spacecraft(mesh, {(200, 200, 200): TEST_SPACECRAFT_MATERIAL}, name=name)


def cube_spacecraft(size: float = 1.0, subdivisions: int = 1):
    """A convex cube [m] centred at the origin.

    Each face is cut into ``2 * 4**(subdivisions - 1)`` facets.

    Parameters
    ----------
    size : float
        Edge length [m].
    subdivisions : int
        1 + number of rounds of :meth:`trimesh.Trimesh.subdivide` (coplanar facets test the
        convexity detection).

    Returns
    -------
    sbrdf_xr.body.spacecraft.Spacecraft

    Examples
    --------
    >>> from sbrdf_xr.testing import cube_spacecraft
    >>> cube_spacecraft()
    <Spacecraft 'cube-1m': 12 facets, materials ['white-paint-a276'], extent [1.0, 1.0, 1.0] m>
    >>> cube_spacecraft(subdivisions=2).n_facets, cube_spacecraft().is_convex
    (48, True)
    """
    import trimesh

    mesh = trimesh.creation.box(extents=(size, size, size))
    for _ in range(subdivisions - 1):
        mesh = mesh.subdivide()
    return _as_spacecraft(mesh, f"cube-{size:g}m")


#: Cross-section of :func:`l_shaped_spacecraft` in xy [m]: the union of [0, 2] x [0, 1] and
#: [0, 1] x [0, 2]; its inner corner is at (1, 1).
L_SECTION = ((0.0, 0.0), (2.0, 0.0), (2.0, 1.0), (1.0, 1.0), (1.0, 2.0), (0.0, 2.0))


def l_shaped_spacecraft(depth: float = 2.0):
    """An L-shaped prism: cross-section :data:`L_SECTION` extruded over z in [0, depth] [m].

    The floor ``y = 1, 1 <= x <= 2`` (normal +y) is shadowed by the wall ``x = 1,
    1 <= y <= 2`` (normal +x) when the Sun has ``s_x < 0``.

    Examples
    --------
    >>> from sbrdf_xr.testing import l_shaped_spacecraft
    >>> body = l_shaped_spacecraft()
    >>> body.n_facets, body.is_convex, round(float(body.mesh.volume), 6)  # 3 m2 x 2 m
    (20, False, 6.0)
    """
    return _as_spacecraft(prism_mesh(L_SECTION, 0.0, depth), "l-shape")


def plate_with_fin_section(
    half_width: float = 1.0,
    thickness: float = 0.1,
    fin_height: float = 1.0,
    fin_thickness: float = 0.1,
) -> np.ndarray:
    """Cross-section in xy of :func:`plate_with_fin_spacecraft` (counter-clockwise) [m].

    Examples
    --------
    >>> from sbrdf_xr.testing import plate_with_fin_section
    >>> plate_with_fin_section().tolist()[:4]
    [[-1.0, -0.1], [1.0, -0.1], [1.0, 0.0], [0.05, 0.0]]
    """
    w, t, h, f = half_width, thickness, fin_height, fin_thickness / 2
    return np.array([(-w, -t), (w, -t), (w, 0.0), (f, 0.0), (f, h), (-f, h), (-f, 0.0), (-w, 0.0)])


def plate_with_fin_spacecraft(depth: float = 2.0, **section):
    """A plate ``[-1, 1] x [-0.1, 0]`` with a perpendicular fin ``[-0.05, 0.05] x [0, 1]``
    (xy, [m]),
    extruded over z in [0, depth]; ``section`` overrides :func:`plate_with_fin_section`.

    Examples
    --------
    The section is 2 x 0.1 of plate and 0.1 x 1 of fin, 0.3 m2, extruded over 2 m:

    >>> from sbrdf_xr.testing import plate_with_fin_spacecraft
    >>> body = plate_with_fin_spacecraft()
    >>> body.n_facets, body.is_convex, round(float(body.mesh.volume), 6)
    (28, False, 0.6)
    """
    return _as_spacecraft(
        prism_mesh(plate_with_fin_section(**section), 0.0, depth), "plate-with-fin"
    )


# ---------------------------------------------------------------- non-convex shadowing bodies

#: Cross-section in xz of :func:`bus_with_panel_spacecraft` [m]: a bus square
#: [-0.5, 0.5] x [-0.5, 0.5], a flat boom [0.5, 1.3] x [-0.03, 0.03] and a panel
#: [1.3, 1.34] x [-0.9, 0.9], counter-clockwise seen from +y.
BUS_PANEL_SECTION = (
    (-0.5, -0.5),
    (0.5, -0.5),
    (0.5, -0.03),
    (1.3, -0.03),
    (1.3, -0.9),
    (1.34, -0.9),
    (1.34, 0.9),
    (1.3, 0.9),
    (1.3, 0.03),
    (0.5, 0.03),
    (0.5, 0.5),
    (-0.5, 0.5),
)


def bus_with_panel_spacecraft(depth: float = 1.0, subdivisions: int = 1):
    """A bus with a solar panel on a boom: :data:`BUS_PANEL_SECTION` (xz) extruded over
    y in [-depth/2, depth/2] [m], one closed surface.

    The panel (1.8 m tall, 0.8 m beyond the bus) shadows the bus's +x face and the boom
    when the Sun is toward +x; the boom shadows the panel's inner face.

    Parameters
    ----------
    depth : float
        Extent along y of bus, boom and panel [m].
    subdivisions : int
        1 + rounds of :meth:`trimesh.Trimesh.subdivide` (4x the facets each).

    Examples
    --------
    Bus 1 x 1, boom 0.8 x 0.06 and panel 0.04 x 1.8 m2 of section, 1 m deep:

    >>> from sbrdf_xr.testing import bus_with_panel_spacecraft
    >>> body = bus_with_panel_spacecraft()
    >>> body.n_facets, body.is_convex, round(float(body.mesh.volume), 6)
    (44, False, 1.12)
    """
    import trimesh

    sec = np.asarray(BUS_PANEL_SECTION, dtype=float)
    # the prism is built in (x, y', z') = (x, z, -y) and rotated so that the section is xz
    mesh = prism_mesh(sec, -depth / 2, depth / 2)
    mesh = trimesh.Trimesh(
        mesh.vertices[:, [0, 2, 1]] * [1.0, -1.0, 1.0], mesh.faces, process=False
    )
    for _ in range(subdivisions - 1):
        mesh = mesh.subdivide()
    return _as_spacecraft(mesh, "bus-with-panel")


#: Antennas of :func:`canx1_with_antennas`: (x, y) of the root [m] on the +Z face, half-width
#: [m], length [m] and the standoff gap between the face and the antenna [m].
CANX1_ANTENNAS = (
    ((0.035, 0.035), (-0.035, 0.035), (-0.035, -0.035), (0.035, -0.035)),
    0.002,
    0.08,
    0.001,
)


def canx1_with_antennas(subdivisions: int = 1, tilt: float = 30.0):
    """CanX-1 (:func:`sbrdf_xr.body.spacecraft.canx1`) with four aluminium whip antennas.

    Each antenna is a closed square rod (4 mm wide, 80 mm long) that rises from a point of
    the +Z face, tilted by ``tilt`` degrees outward (away from the z axis), standing 1 mm off
    the face (the surface stays a union of disjoint closed parts, so no facet is partly
    buried).  The rods shadow the +Z face and each other's neighbourhood; the raised cells
    shadow the side faces as in CanX-1.

    Parameters
    ----------
    subdivisions : int
        1 + rounds of :meth:`trimesh.Trimesh.subdivide` of the whole mesh (4x the facets
        each: 732, 2928, 11712, 46848, ...).
    tilt : float
        Tilt of the rods from the +z axis [degree].

    Returns
    -------
    sbrdf_xr.body.spacecraft.Spacecraft

    Examples
    --------
    CanX-1's 684 facets and 12 per rod:

    >>> from sbrdf_xr.testing import canx1_with_antennas
    >>> body = canx1_with_antennas()
    >>> body.name, body.n_facets, body.is_convex
    ('canx1-antennas', 732, False)
    """
    import trimesh

    from .body.spacecraft import Spacecraft, canx1

    base = canx1()
    roots, half, length, gap = CANX1_ANTENNAS
    parts = [base.mesh]
    labels = [base.facet_material]
    t = np.radians(tilt)
    for x, y in roots:
        rod = trimesh.creation.box(extents=(2 * half, 2 * half, length))
        rod.apply_translation((0.0, 0.0, length / 2))
        outward = np.array([x, y, 0.0]) / np.hypot(x, y)
        axis = np.cross([0.0, 0.0, 1.0], outward)
        rod.apply_transform(trimesh.transformations.rotation_matrix(t, axis))
        # lift so that the lowest vertex stands gap above the face z = 0.05
        lift = 0.05 + gap - rod.vertices[:, 2].min()
        rod.apply_translation((x, y, lift))
        parts.append(rod)
        labels.append(np.full(len(rod.faces), "aluminium-6061-t6"))
    mesh = trimesh.Trimesh(
        np.vstack([p.vertices for p in parts]),
        np.vstack(
            [
                p.faces + off
                for p, off in zip(
                    parts, np.cumsum([0] + [len(p.vertices) for p in parts[:-1]]), strict=True
                )
            ]
        ),
        process=False,
    )
    label = np.concatenate(labels)
    for _ in range(subdivisions - 1):
        mesh = mesh.subdivide()
        label = np.repeat(label, 4)  # trimesh.subdivide keeps each face's 4 children together
    return Spacecraft(mesh, label, name="canx1-antennas", colors=base.colors)


# ---------------------------------------------------------------- cubes


def _spectrum(wavelength: np.ndarray) -> np.ndarray:
    """A smooth reddish reflectance shape (1 at 550 nm) with a dip near 700 nm."""
    w = np.asarray(wavelength, dtype=np.float64)
    return (1.0 + 4e-4 * (w - 550.0)) * (1.0 - 0.3 * np.exp(-(((w - 700.0) / 40.0) ** 2)))


def rotation_cube(n_attitudes: int = 72, phase_angles=(10.0,)) -> xr.Dataset:
    """A synthetic rotation sweep with four glints, shaped like a simulated cube.

    ``brdf`` [sr-1 nm], ``signal`` and ``spacecraft_sbrdf`` over 400-1100 nm, ``area``;
    the glints at 25, 115, 205 and 295 deg rise a hundredfold over a diffuse base.  For
    tests and examples of figures: no catalog table is read.

    Examples
    --------
    >>> from sbrdf_xr.testing import rotation_cube
    >>> cube = rotation_cube()
    >>> dict(cube.sizes), cube.brdf.attrs["units"]
    ({'attitude': 72, 'phase_angle': 1, 'wavelength': 36}, 'sr-1 nm')
    """
    ang = np.arange(n_attitudes) * 360.0 / n_attitudes
    beta = np.asarray(phase_angles, dtype=np.float64)
    wl = np.arange(400.0, 1101.0, 20.0)
    d = (ang[:, None] - 25.0 + 45.0) % 90.0 - 45.0  # angle from the nearest glint [degree]
    level = 0.01 * (1.0 + 100.0 * np.exp(-((d / 3.0) ** 2))) * np.cos(np.radians(beta / 2.0))
    sig = level[..., None] * _spectrum(wl)  # (attitude, phase_angle, wavelength) [m2 sr-1]
    area = np.full(level.shape, 0.02)
    sbrdf = sig / area[..., None]
    dims = ("attitude", "phase_angle", "wavelength")
    return xr.Dataset(
        {
            "spacecraft_sbrdf": (dims, sbrdf, {"units": "sr-1", "long_name": "overall sBRDF"}),
            "signal": (dims, sig, {"units": "m2 sr-1", "long_name": "radiometric signal"}),
            "brdf": (dims[:2], np.trapezoid(sbrdf, wl, axis=-1), {"units": "sr-1 nm"}),
            "area": (dims[:2], area, {"units": "m2", "long_name": "contributing area"}),
        },
        coords={
            "attitude": np.arange(n_attitudes),
            "attitude_angle": ("attitude", ang, {"units": "degree"}),
            "phase_angle": ("phase_angle", beta, {"units": "degree"}),
            "wavelength": ("wavelength", wl, {"units": "nm"}),
        },
        attrs={"scene": "synthetic-rotation"},
    )


def pass_cube(n_times: int = 121) -> xr.Dataset:
    """A synthetic pass over time that leaves the Earth's shadow, shaped like a simulated cube.

    One sample a second from 2024-03-17T01:20:00 UTC: umbra for the first 20 s, penumbra
    for 10 s (``umbra_exit``, ``penumbra_exit`` attributes), then sunlight; ``range``
    [km], ``phase_angle``, ``elevation`` [degree], ``sunlit_fraction`` and ``signal``
    over 400-1100 nm.  No orbit is propagated and no table read.

    Examples
    --------
    >>> from sbrdf_xr.testing import pass_cube
    >>> cube = pass_cube()
    >>> cube.sizes["time"], cube.attrs["umbra_exit"], float(cube.sunlit_fraction[-1])
    (121, '2024-03-17T01:20:20.000', 1.0)
    """
    s = np.arange(n_times, dtype=np.float64)
    t = np.datetime64("2024-03-17T01:20:00", "ns") + (s * 1e9).astype("timedelta64[ns]")
    frac = np.clip((s - 20.0) / 10.0, 0.0, 1.0)
    elevation = 20.0 + 50.0 * np.sin(np.pi * s / max(n_times - 1, 1))
    phase = 50.0 + 60.0 * s / max(n_times - 1, 1)
    wl = np.arange(400.0, 1101.0, 20.0)
    level = 1e-4 * frac * (1.5 + np.cos(2 * np.pi * s / 30.0)) * np.cos(np.radians(phase / 2))
    sig = level[:, None] * _spectrum(wl)
    coord = {"units": "degree"}
    return xr.Dataset(
        {"signal": (("time", "wavelength"), sig, {"units": "m2 sr-1"})},
        coords={
            "time": ("time", t),
            "wavelength": ("wavelength", wl, {"units": "nm"}),
            "range": ("time", 1500.0 - 8.0 * elevation, {"units": "km"}),
            "phase_angle": ("time", phase, coord),
            "elevation": ("time", elevation, coord),
            "sunlit_fraction": ("time", frac, {"units": "1"}),
        },
        attrs={
            "scene": "synthetic-pass",
            "orbit_name": "a synthetic orbit",
            "site_name": "a synthetic site",
            "penumbra_entry": "",
            "umbra_entry": "",
            "umbra_exit": "2024-03-17T01:20:20.000",
            "penumbra_exit": "2024-03-17T01:20:30.000",
        },
    )


def plate_spacecraft(
    size: tuple[float, float] = (1.0, 2.0), front: str = "cell", back: str | None = "backsheet"
):
    """An open flat plate in the plane z = 0 [m], front towards +z, two triangles.

    Parameters
    ----------
    size : (float, float)
        Extent along x and y [m].
    front, back : str
        Materials of the front and of the back (None: one-sided).

    Examples
    --------
    >>> from sbrdf_xr.testing import plate_spacecraft
    >>> plate = plate_spacecraft()
    >>> plate.n_facets, plate.n_sides, plate.materials
    (2, 4, ['backsheet', 'cell'])
    """
    import trimesh

    from .body.spacecraft import Spacecraft

    a, b = size
    mesh = trimesh.Trimesh(
        np.array([[0, 0, 0], [a, 0, 0], [a, b, 0], [0, b, 0]], dtype=float),
        [[0, 1, 2], [0, 2, 3]],
        process=False,
    )
    return Spacecraft(mesh, [front] * 2, name="plate", back_material=back)


def box_with_plate_spacecraft(height: float = 1.0, parts: bool = False, law=None):
    """A closed unit cube (``bus``, centred at the origin) and a two-sided 1 x 1 m plate
    ``height`` [m] above its top face (``cell`` in front, towards +z, ``backsheet``
    behind): a mixed open and closed body.

    With ``parts=True`` the plate is the part ``"array"`` hinged about the x axis through
    its centre (``law``: its pointing law, default sun-tracking).

    Examples
    --------
    >>> from sbrdf_xr.testing import box_with_plate_spacecraft
    >>> body = box_with_plate_spacecraft()
    >>> body.n_facets, body.n_sides, body.is_convex
    (14, 16, False)
    >>> box_with_plate_spacecraft(parts=True).moving_parts[0].name
    'array'
    """
    import trimesh

    from .body.parts import Part, SunTracking
    from .body.spacecraft import Spacecraft

    box = trimesh.creation.box()
    z = 0.5 + height
    v = np.vstack([box.vertices, [[-0.5, -0.5, z], [0.5, -0.5, z], [0.5, 0.5, z], [-0.5, 0.5, z]]])
    f = np.vstack([box.faces, [[8, 9, 10], [8, 10, 11]]])
    mesh = trimesh.Trimesh(v, f, process=False)
    mats = ["bus"] * 12 + ["cell"] * 2
    backs = [""] * 12 + ["backsheet"] * 2
    plist: tuple[Part, ...] = ()
    if parts:
        law = SunTracking() if law is None else law
        plist = (Part("array", [12, 13], axis=[1.0, 0, 0], point=[0, 0, z], law=law),)
    return Spacecraft(mesh, mats, name="box-with-plate", back_material=backs, parts=plist)
