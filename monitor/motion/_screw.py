r"""Screw linear interpolation (constant twist) between rigid poses, numpy only.

A segment from pose (R0, x0) to (R1, x1) (world frame, body origin x) is the SE(3)
geodesic X(s) = exp(s xi) X0, s in [0, 1], with the WORLD twist xi = (omega, v)
(rad and m per unit s) of X1 X0^{-1}. Its rotation is exactly the shortest-arc slerp
R(s) = Rot(omega s) R0 (so :class:`monitor.motion._kinematics.QuatTrack` supplies it),
and a world point y of the body at s = 0 moves to

    exp(s xi) y = y + s sinc1(phi) omega x y + s^2 a(phi) omega x (omega x y)
                  + s v + s^2 a(phi) omega x v + s^3 b(phi) omega x (omega x v),

phi = s |omega|, sinc1 = sin(phi)/phi, a = (1 - cos phi)/phi^2, b = (phi - sin phi)/phi^3,
i.e. exp(s [omega]) y + V(s omega) s v. v = V(omega)^{-1} (x1 - exp([omega]) x0) with
V^{-1}(omega) = I - [omega]/2 + c(|omega|) [omega]^2, c(th) = (1 - (th/2) cot(th/2)) / th^2.
All coefficient functions use series near 0, so a pure translation (omega = 0) is the lerp.

The point moves on a helix about the screw axis (direction u = omega/|omega|): its velocity
omega x y + v splits into the axial part d = u . v (the same for every point) and the
perpendicular part of constant length P(y) = |omega x y + v - d u| = |omega| dist(y, axis).
Over a parameter span sigma from any parameter s0 the displacement is EXACTLY

    |X(s0 + sigma) y' - X(s0) y'| = sigma sqrt(d^2 + (sinc(|omega| sigma / 2) P)^2)

(chord of the circle of radius dist(y, axis) through the angle |omega| sigma, and the
axial advance d sigma; the two are orthogonal). :func:`helix_span` evaluates it.
"""

from __future__ import annotations

import numpy as np


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.cross(a, b)


def _sinc1(phi: np.ndarray) -> np.ndarray:
    """sin(phi)/phi."""
    return np.sinc(phi / np.pi)


def _a(phi: np.ndarray) -> np.ndarray:
    """(1 - cos phi) / phi^2 = sinc(phi/2)^2 / 2."""
    return 0.5 * np.sinc(phi / (2.0 * np.pi)) ** 2


def _b(phi: np.ndarray) -> np.ndarray:
    """(phi - sin phi) / phi^3, series below 0.1."""
    phi = np.asarray(phi, float)
    p2 = phi * phi
    series = 1 / 6 - p2 / 120 + p2**2 / 5040 - p2**3 / 362880 + p2**4 / 39916800
    safe = np.where(phi < 0.1, 1.0, phi)
    direct = (safe - np.sin(safe)) / safe**3
    return np.where(phi < 0.1, series, direct)


def _c(th: np.ndarray) -> np.ndarray:
    """(1 - (th/2) cot(th/2)) / th^2, series below 0.1 (th in [0, pi])."""
    th = np.asarray(th, float)
    t2 = th * th
    series = 1 / 12 + t2 / 720 + t2**2 / 30240 + t2**3 / 1209600
    safe = np.where(th < 0.1, 1.0, th)
    h = 0.5 * safe
    direct = (1.0 - h * np.cos(h) / np.sin(h)) / safe**2
    return np.where(th < 0.1, series, direct)


def rotate(omega: np.ndarray, s: np.ndarray, y: np.ndarray) -> np.ndarray:
    """exp(s [omega]) y for omega (..., 3), s (...), y (..., 3)."""
    th = np.linalg.norm(omega, axis=-1)
    phi = s * th
    wy = _cross(omega, y)
    return y + (s * _sinc1(phi))[..., None] * wy + (s * s * _a(phi))[..., None] * _cross(omega, wy)


def twist_translation(omega: np.ndarray, x0: np.ndarray, x1: np.ndarray) -> np.ndarray:
    """The linear part v (..., 3) of the world twist taking origin x0 to x1 with rotation omega."""
    th = np.linalg.norm(omega, axis=-1)
    t = x1 - rotate(omega, np.ones_like(th), x0)
    wt = _cross(omega, t)
    return t - 0.5 * wt + _c(th)[..., None] * _cross(omega, wt)


def screw_point(omega: np.ndarray, v: np.ndarray, s: np.ndarray, y: np.ndarray) -> np.ndarray:
    """exp(s xi) y for the twist (omega, v) (..., 3), parameters s (...) and points y (..., 3)."""
    th = np.linalg.norm(omega, axis=-1)
    phi = s * th
    wv = _cross(omega, v)
    return (rotate(omega, s, y) + s[..., None] * v + (s * s * _a(phi))[..., None] * wv
            + (s**3 * _b(phi))[..., None] * _cross(omega, wv))


def helix_speeds(omega: np.ndarray, v: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Axial speed |d| (...) and perpendicular speed P (...) of world point y under (omega, v)."""
    th = np.linalg.norm(omega, axis=-1)
    safe = np.where(th > 0.0, th, 1.0)
    u = omega / safe[..., None]
    d = np.where(th > 0.0, np.einsum("...i,...i->...", u, v), 0.0)
    vel = _cross(omega, y) + v
    # for omega = 0 every point translates by v: all of it counts as "axial"
    d = np.where(th > 0.0, d, np.linalg.norm(v, axis=-1))
    perp = np.where(th[..., None] > 0.0, vel - d[..., None] * u, 0.0)
    return np.abs(d), np.linalg.norm(perp, axis=-1)


def helix_span(d: np.ndarray, P: np.ndarray, th: np.ndarray, sigma: np.ndarray) -> np.ndarray:
    """Displacement sigma sqrt(d^2 + (sinc(th sigma / 2) P)^2) of a helix point over span sigma in [0, 1]."""
    sigma = np.clip(sigma, 0.0, 1.0)
    return sigma * np.hypot(d, np.sinc(th * sigma / (2.0 * np.pi)) * P)


__all__ = ["helix_span", "helix_speeds", "rotate", "screw_point", "twist_translation"]
