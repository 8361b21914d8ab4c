"""A closed sphere under internal pressure as a plate body, with seams and poles: once as
OpenCASCADE's one periodic face, once as two hemispheres that share both poles.

Reference: the uniform dilation ``d = (w/R) x``. On a sphere of radius ``R``
``Δ_S x = −2 x / R²`` and ``Δ_S² x = 4 x / R⁴``, so the intrinsic plate under tension
``−T Δ_S d + D Δ_S² d = q n`` (``n = x/R``) has the radial displacement

.. math:: w = \\frac{q R^2}{2 T + 4 D / R^2},

the membrane's ``q R² / (2T)`` at ``D = 0`` (the analogue of the shell's
``p R² (1 − ν) / (2 E t)``, Timoshenko & Woinowsky-Krieger §129) and ``q R⁴ / (4D)`` at
``T = 0``. The sphere is free: a pressure on a closed surface has no resultant, and the
equilibrium is taken with the mean motion held at zero
(:func:`splinedeform.pipeline_body.body_static`), which leaves the dilation untouched.
"""

from __future__ import annotations

from math import pi

import numpy as np
import pytest

import splinedeform as sd
from splinedeform.pipeline_body import body_static
from splinedeform.refine import refine_surface

import body_patches

R, Q = 2.0, 1.0
SAMPLES = 17


def dilation(material: sd.Material) -> float:
    """Radial displacement of the module docstring."""
    return Q * R ** 2 / (2 * material.w10 + 4 * material.w20 / R ** 2)


@pytest.fixture(scope="module")
def step_sphere(tmp_path_factory) -> sd.Surface:
    """OpenCASCADE's sphere of radius ``R`` through a STEP file and the body reader, degree
    2 → 3 with 2 knots into every span (16 × 11 control points)."""
    pytest.importorskip("OCP", reason="the 'cad-step' extra (cadquery-ocp) is not installed")
    from OCP.BRepBuilderAPI import BRepBuilderAPI_NurbsConvert
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeSphere
    from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer

    from splinedeform.cad_body import read_body

    path = tmp_path_factory.mktemp("sphere") / "sphere.step"
    shape = BRepBuilderAPI_NurbsConvert(BRepPrimAPI_MakeSphere(R).Shape(), True).Shape()
    writer = STEPControl_Writer()
    assert writer.Transfer(shape, STEPControl_AsIs) == 1
    assert writer.Write(str(path)) == 1
    (surface,), topology, _ = read_body(path)
    assert topology.counts["seam"] == 1
    return refine_surface(surface, elevate=(1, 1), insert=(2, 2))


def grid(surface: sd.Surface) -> tuple[np.ndarray, np.ndarray]:
    (u0, u1), (v0, v1) = surface.domain
    return np.meshgrid(np.linspace(u0, u1, SAMPLES), np.linspace(v0, v1, SAMPLES),
                       indexing="ij")


def radial(solution, surface: sd.Surface, patch: int) -> np.ndarray:
    """Radial displacement ``d · x / |x|`` on a ``SAMPLES²`` grid of ``surface``."""
    U, V = grid(surface)
    X = surface.evaluate(U, V)
    return np.sum(solution.displacement(U, V, patch=patch) * X, -1) / np.linalg.norm(X, axis=-1)


@pytest.mark.parametrize("material", [sd.Material(w10=1.0, w01=1.0),
                                      sd.Material(w10=1.0, w01=1.0, w20=0.4, w11=0.4, w02=0.4),
                                      sd.Material(w20=1.0, w11=1.0, w02=1.0)],
                         ids=["membrane", "tension and bending", "bending"])
def test_one_periodic_face_with_a_seam_and_two_poles(step_sphere, material):
    surface = step_sphere
    body = sd.Body([surface])
    assert body.summary()["seam"] == 1 and body.summary()["poles"] == 2
    model = sd.BodyModel(body, material)
    # nothing holds it: one constant translation per coordinate, counted on the spectrum
    # where there is no tension (a harmonic field on a closed surface is constant)
    assert model.rigid_modes == 1
    if material.w20:
        # the rest sphere is C1 across its seam: the slope is tied exactly, no penalty
        assert model.constraints.ties.interfaces == {0}
    solution = body_static(model, sd.Pressure(Q))
    W = dilation(material)
    # the rational basis reproduces x, so the dilation is in the space: what is left is
    # the solve's round-off (measured 2.7e-10 of W); the issue asks 1 %
    np.testing.assert_allclose(radial(solution, surface, 0), W, rtol=1e-8)
    # the seam: both sides are the same merged control points (measured 0); each pole moves
    # as one point (its points are one class)
    (u0, u1), (v0, v1) = surface.domain
    v = np.linspace(v0, v1, SAMPLES)
    gap = (solution.displacement(np.full_like(v, u0), v, patch=0)
           - solution.displacement(np.full_like(v, u1), v, patch=0))
    assert np.abs(gap).max() <= 1e-9 * W
    u = np.linspace(u0, u1, SAMPLES)
    for pole in (v0, v1):
        spread = np.ptp(solution.displacement(u, np.full_like(u, pole), patch=0), axis=0)
        assert spread.max() <= 1e-12 * W


def hemisphere(start: float) -> sd.Surface:
    """:func:`body_patches.hemisphere` of radius ``R``, 8 × 8 cells."""
    return body_patches.hemisphere(R, start)


@pytest.mark.parametrize("material", [sd.Material(w10=1.0, w01=1.0),
                                      sd.Material(w10=1.0, w01=1.0, w20=0.4, w11=0.4, w02=0.4)],
                         ids=["membrane", "tension and bending"])
def test_two_hemispheres_share_their_poles(material):
    patches = [hemisphere(0.0), hemisphere(pi)]
    body = sd.Body(patches)
    assert body.summary()["shared"] == 2 and body.summary()["poles"] == 4
    model = sd.BodyModel(body, material)
    assert model.rigid_modes == 1
    solution = body_static(model, sd.Pressure(Q))
    W = dilation(material)
    # the polynomial patches only approximate the sphere (cells crowded at the poles):
    # measured within 1.7e-4 (membrane) and 1.9e-4 of W; the issue asks 1 %
    for k, surface in enumerate(patches):
        np.testing.assert_allclose(radial(solution, surface, k), W, rtol=1e-3)
    # the meridians: merged control points, so the deformed edges meet to round-off
    v = np.linspace(0.0, pi, SAMPLES)
    for i in body.topology.interfaces:
        ends = {"u0": 0.0, "u1": pi}
        a = solution.displacement(np.full_like(v, ends[i.edge_a]), v, patch=i.a)
        b = solution.displacement(np.full_like(v, ends[i.edge_b]), v, patch=i.b)
        assert np.abs(a - (b[::-1] if i.reversed else b)).max() <= 1e-9 * W
    # each pole is one point of both patches
    u = np.linspace(0.0, pi, SAMPLES)
    for pole in (0.0, pi):
        points = np.concatenate([solution.displacement(u, np.full_like(u, pole), patch=k)
                                 for k in range(2)])
        assert np.ptp(points, axis=0).max() <= 1e-12 * W
