"""Ray casting of a hole in a machined plate: surface, chamfer cone, bore wall, burr, highlight.

Geometry in the hole's local frame: z along the hole normal (out of the material, toward
the camera), the surface is the plane z = 0, the bore is the cylinder ρ = r for
-depth ≤ z ≤ -chamfer, the 45° chamfer is the cone ρ = r + chamfer + z for -chamfer ≤ z ≤ 0.
A burr (occluder) is a flat flap on the surface covering the rim over an azimuth range;
a specular highlight is a bright streak across the rim. Optionally the chamfer is shaded
as a rounded lip (brightness falling from the surface level to dark as its normal turns
from the view toward the bore, a soft edge), the wall is lit from one side (directional
light, the other side in shadow) and a bright disc with radial marks (a screw head) sits
inside the bore. Values are fractions of full scale
before vignetting.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from measure.synth.texture import TEXEL_M, sample_texture


@dataclass(frozen=True)
class Shading:
    """Brightness levels (fractions of full scale) and appearance parameters."""

    surface: float
    chamfer: float
    wall: float
    bottom: float
    burr: float
    texture_amplitude: float
    highlight: float  # peak added brightness of the highlight (0: none)
    highlight_azimuth: float
    occlusion_fraction: float
    occlusion_azimuth: float
    texture_offset: tuple[float, float]
    light_azimuth: float = 0.0  # direction (in the hole plane) the light comes from
    wall_light: float = 0.0  # wall brightness modulation with azimuth (0: even)
    object_radius: float = 0.0  # a disc (screw head) inside the bore, radius (m; 0: none)
    object_depth: float = 0.0  # its depth below the surface (m)
    object_level: float = 0.0  # its brightness
    lip_rounded: bool = False  # the chamfer cone is shaded as a rounded lip


@dataclass(frozen=True)
class HoleGeometry:
    """A hole in one camera's optical frame (metres)."""

    center: np.ndarray
    normal: np.ndarray
    e1: np.ndarray
    e2: np.ndarray
    radius: float
    chamfer: float
    depth: float

    @property
    def rotation(self) -> np.ndarray:
        """Columns e1, e2, normal: maps local coordinates into camera coordinates."""
        return np.stack([self.e1, self.e2, self.normal], axis=1)

    def transformed(self, R: np.ndarray, T: np.ndarray) -> HoleGeometry:
        """The same hole in another frame, ``X' = R X + T``."""
        return HoleGeometry(
            center=R @ self.center + T,
            normal=R @ self.normal,
            e1=R @ self.e1,
            e2=R @ self.e2,
            radius=self.radius,
            chamfer=self.chamfer,
            depth=self.depth,
        )

    def plane_hit(self, nx: np.ndarray, ny: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Local (x, y) where rays through normalised coords hit the surface plane z = 0."""
        o, d = self._rays(nx, ny)
        t0 = -o[2] / d[2]
        return o[0] + t0 * d[0], o[1] + t0 * d[1]

    def _rays(self, nx: np.ndarray, ny: np.ndarray) -> tuple[np.ndarray, list[np.ndarray]]:
        Rt = self.rotation.T
        o = Rt @ (-self.center)
        d = [Rt[i, 0] * nx + Rt[i, 1] * ny + Rt[i, 2] for i in range(3)]
        return o, d


def _surface_texture(x: np.ndarray, y: np.ndarray, sh: Shading) -> np.ndarray:
    tx = (x + sh.texture_offset[0]) / TEXEL_M
    ty = (y + sh.texture_offset[1]) / TEXEL_M
    return 1.0 + sh.texture_amplitude * sample_texture(tx, ty).astype(np.float64)


def _highlight(x: np.ndarray, y: np.ndarray, r: float, sh: Shading) -> np.ndarray:
    if sh.highlight <= 0:
        return np.zeros_like(x)
    c, s = np.cos(sh.highlight_azimuth), np.sin(sh.highlight_azimuth)
    a = x * c + y * s - r
    b = -x * s + y * c
    sa, sb = 0.35 * r, max(0.06 * r, 2e-4)
    return sh.highlight * np.exp(-0.5 * ((a / sa) ** 2 + (b / sb) ** 2))


def _in_burr(x: np.ndarray, y: np.ndarray, geo: HoleGeometry, sh: Shading) -> np.ndarray:
    if sh.occlusion_fraction <= 0:
        return np.zeros(x.shape, dtype=bool)
    rho = np.hypot(x, y)
    half = 0.12 * geo.radius + geo.chamfer
    rel = np.mod(np.arctan2(y, x) - sh.occlusion_azimuth, 2 * np.pi)
    return (np.abs(rho - geo.radius - 0.5 * geo.chamfer) < half) & (
        rel < 2 * np.pi * sh.occlusion_fraction
    )


def shade(geo: HoleGeometry, sh: Shading, nx: np.ndarray, ny: np.ndarray) -> np.ndarray:
    """Brightness (fraction of full scale) seen along rays through normalised coords."""
    o, d = geo._rays(nx, ny)
    t0 = -o[2] / d[2]
    x0, y0 = o[0] + t0 * d[0], o[1] + t0 * d[1]
    rho0 = np.hypot(x0, y0)
    r, ch = geo.radius, geo.chamfer
    out = sh.surface * _surface_texture(x0, y0, sh) + _highlight(x0, y0, r, sh)
    burr = _in_burr(x0, y0, geo, sh)
    inside = (rho0 < r + ch) & ~burr
    if burr.any():
        out[burr] = sh.burr * _surface_texture(x0[burr], y0[burr], sh) + _highlight(
            x0[burr], y0[burr], r, sh
        )
    if not inside.any():
        return out
    ox, oy, oz = o
    dx, dy, dz = (c[inside] for c in d)
    ti = t0[inside]
    val = np.full(dx.shape, sh.bottom)
    done = np.zeros(dx.shape, dtype=bool)
    if ch > 0:
        k = r + ch + oz
        A = dx * dx + dy * dy - dz * dz
        B = 2.0 * (ox * dx + oy * dy - k * dz)
        C = ox * ox + oy * oy - k * k
        disc = np.maximum(B * B - 4 * A * C, 0.0)
        sq = np.sqrt(disc)
        best = np.full(dx.shape, np.inf)
        with np.errstate(divide="ignore", invalid="ignore"):
            for t in ((-B - sq) / (2 * A), (-B + sq) / (2 * A)):
                z = oz + t * dz
                ok = (t > ti - 1e-12) & (z <= 1e-12) & (z >= -ch) & (k + t * dz >= 0)
                best = np.where(ok & (t < best), t, best)
        hit = np.isfinite(best)
        hx, hy = ox + best[hit] * dx[hit], oy + best[hit] * dy[hit]
        az = np.arctan2(hy, hx)
        if sh.lip_rounded:  # quarter round of radius ch, Lambert under light along the axis:
            frac = np.clip((r + ch - np.hypot(hx, hy)) / ch, 0.0, 1.0)  # sin(normal angle)
            level = sh.surface * np.sqrt(1.0 - frac * frac) + sh.wall * frac
        else:
            level = sh.chamfer * (1.0 + 0.15 * np.cos(az - 0.8))
        val[hit] = level * _surface_texture(hx, hy, sh) + 0.6 * _highlight(hx, hy, r, sh)
        done |= hit
    a = dx * dx + dy * dy
    b = 2.0 * (ox * dx + oy * dy)
    c = ox * ox + oy * oy - r * r
    with np.errstate(divide="ignore", invalid="ignore"):
        t_exit = (-b + np.sqrt(np.maximum(b * b - 4 * a * c, 0.0))) / (2 * a)
    zw = oz + t_exit * dz
    wall = ~done & np.isfinite(t_exit) & (zw >= -geo.depth) & (zw <= -ch + 1e-12)
    frac = np.clip(-zw[wall] / geo.depth, 0.0, 1.0)
    hx, hy = ox + t_exit[wall] * dx[wall], oy + t_exit[wall] * dy[wall]
    lit = 1.0 + sh.wall_light * np.cos(np.arctan2(hy, hx) - sh.light_azimuth - np.pi)
    val[wall] = sh.wall * lit * (1.0 - 0.7 * frac) + 0.5 * _highlight(hx, hy, r, sh) * np.exp(
        zw[wall] / (0.15 * r)
    )
    if sh.object_radius > 0:  # a screw head: a disc at object_depth, in front of the rest
        with np.errstate(divide="ignore", invalid="ignore"):
            t_obj = (-sh.object_depth - oz) / dz
        px_, py_ = ox + t_obj * dx, oy + t_obj * dy
        on = ~done & (np.hypot(px_, py_) < sh.object_radius) & (t_obj > ti)
        marks = 0.5 + 0.5 * np.cos(4.0 * np.arctan2(py_[on], px_[on]))
        val[on] = sh.object_level * (0.6 + 0.4 * marks)
    out[inside] = val
    return out
