"""Image error against ground truth: what an accuracy setting loses.

Hit-mask disagreement is split into *holes* (the truth hits, the image misses) and *false
hits* (the image hits empty space), each also counted off the silhouette, where no LOD
threshold explains it. Depth error is measured in units of the LOD threshold ε(t) =
footprint × t [KRS17 §4], so "within 1" means "as close as the tracer was asked to stop".
The GPU-vs-reference pixel tests use :func:`agreement` from here too.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..frame import Frame

SSIM_WINDOW = 7  # pixels on a side of SSIM's local window
SSIM_C1, SSIM_C2 = 0.01**2, 0.03**2  # Wang et al. 2004's constants for a range of 1


def silhouette(hit: np.ndarray) -> np.ndarray:
    """Pixels with a 4-neighbour of the other hit state (both sides of every outline)."""
    s = np.zeros_like(hit)
    s[1:] |= hit[1:] != hit[:-1]
    s[:-1] |= hit[1:] != hit[:-1]
    s[:, 1:] |= hit[:, 1:] != hit[:, :-1]
    s[:, :-1] |= hit[:, 1:] != hit[:, :-1]
    return s


def _box_mean(x: np.ndarray, k: int) -> np.ndarray:
    """Mean over k×k windows ('valid' positions), by summed-area tables."""
    c = np.pad(x, ((1, 0), (1, 0))).cumsum(0).cumsum(1)
    return (c[k:, k:] - c[:-k, k:] - c[k:, :-k] + c[:-k, :-k]) / (k * k)


def ssim(a: np.ndarray, b: np.ndarray, k: int = SSIM_WINDOW) -> float:
    """Mean structural similarity of two images in [0, 1] (luminance of RGB), uniform k×k
    windows [Wang et al. 2004]; 1 for identical images."""
    if a.ndim == 3:
        w = np.array([0.2126, 0.7152, 0.0722])
        a, b = a @ w, b @ w
    if min(a.shape) < k:
        k = min(a.shape)
    ma, mb = _box_mean(a, k), _box_mean(b, k)
    va = _box_mean(a * a, k) - ma * ma
    vb = _box_mean(b * b, k) - mb * mb
    cov = _box_mean(a * b, k) - ma * mb
    s = ((2 * ma * mb + SSIM_C1) * (2 * cov + SSIM_C2)) / (
        (ma * ma + mb * mb + SSIM_C1) * (va + vb + SSIM_C2)
    )
    return float(s.mean())


def psnr(a: np.ndarray, b: np.ndarray) -> float:
    """Peak signal-to-noise ratio in dB for images in [0, 1]; inf when identical."""
    mse = float(np.mean((np.clip(a, 0, 1) - np.clip(b, 0, 1)) ** 2))
    return math.inf if mse == 0 else 10.0 * math.log10(1.0 / mse)


@dataclass(frozen=True)
class Errors:
    holes: float  # fraction of pixels: truth hits, image misses
    false_hits: float  # fraction of pixels: image hits, truth misses
    holes_off_silhouette: float
    false_hits_off_silhouette: float
    depth_eps_median: float  # |t − t_truth| / ε(t_truth) on common hits
    depth_eps_p99: float
    normal_deg_median: float  # angle between normals on common hits
    normal_deg_p99: float
    psnr: float  # colour, dB
    ssim: float
    iterations: float  # mean per pixel
    capped: float  # fraction of pixels whose ray spent the cap without a verdict

    @property
    def mask_error(self) -> float:
        """All hit-mask disagreement: holes + false hits."""
        return self.holes + self.false_hits


def compare(image: Frame, truth: Frame, eps_per_t: float, cap: int) -> Errors:
    """Errors of ``image`` against ``truth``; ``eps_per_t`` is the footprint per unit ray
    distance (the unit of depth error), ``cap`` the image's iteration cap."""
    holes = truth.hit & ~image.hit
    false = image.hit & ~truth.hit
    off = ~silhouette(truth.hit)
    both = image.hit & truth.hit
    t = truth.depth[both]
    dt = np.abs(image.depth[both] - t) / np.maximum(eps_per_t * t, 1e-300)
    cos = np.clip((image.normal * truth.normal).sum(-1)[both], -1.0, 1.0)
    ang = np.degrees(np.arccos(cos))

    def q(x: np.ndarray, p: float) -> float:
        return float(np.percentile(x, p)) if x.size else 0.0

    n = holes.size
    return Errors(
        holes=holes.sum() / n,
        false_hits=false.sum() / n,
        holes_off_silhouette=(holes & off).sum() / n,
        false_hits_off_silhouette=(false & off).sum() / n,
        depth_eps_median=q(dt, 50),
        depth_eps_p99=q(dt, 99),
        normal_deg_median=q(ang, 50),
        normal_deg_p99=q(ang, 99),
        psnr=psnr(image.color, truth.color),
        ssim=ssim(image.color, truth.color),
        iterations=float(image.iterations.mean()),
        capped=float(((image.iterations >= cap) & ~image.hit).mean()),
    )


def error_image(image: Frame, truth: Frame) -> np.ndarray:
    """RGB8 picture of the hit-mask errors over the dimmed truth: holes red, false hits blue."""
    out = (truth.rgb8().astype(np.float64) * 0.35 + 40).astype(np.uint8)
    out[truth.hit & ~image.hit] = (255, 40, 40)
    out[image.hit & ~truth.hit] = (60, 120, 255)
    return out


EDGE_DEPTH_JUMP = 0.01  # a 4-neighbour 1 % nearer or farther marks an occlusion edge


def edges(b: Frame) -> np.ndarray:
    """Occlusion edges: the silhouette, and pixels with a 4-neighbour at a depth more than
    EDGE_DEPTH_JUMP apart (an outline in front of another surface). Only there may two
    correct tracers legitimately differ: a ray one step later slips past the outline."""
    e = silhouette(b.hit)
    d = np.where(b.hit, b.depth, 0.0)
    for ax in (0, 1):
        a1, e1 = np.swapaxes(d, 0, ax), np.swapaxes(e, 0, ax)
        jump = np.abs(a1[1:] - a1[:-1]) > EDGE_DEPTH_JUMP * np.minimum(a1[1:], a1[:-1])
        e1[1:] |= jump
        e1[:-1] |= jump
    return e


@dataclass(frozen=True)
class Agreement:
    """How closely two renders of one scene agree (the GPU-vs-reference pixel tests)."""

    hit: float  # fraction of pixels with equal hit mask
    depth_close: float  # fraction of common hits with relative depth error ≤ depth_rel
    normal_close: float  # fraction of common hits with normal angle ≤ normal_deg
    color: float  # fraction of pixels with every channel within color_tol
    # away from every occlusion edge (of either image), the worst pixel:
    off_edge_hit: int = 0  # pixels with different hit state
    off_edge_depth: float = 0.0  # largest relative depth error of a common hit
    off_edge_color: float = 0.0  # largest channel error


def agreement(
    a: Frame,
    b: Frame,
    depth_rel: float,
    normal_deg: float,
    color_tol: float,
    ties: np.ndarray | None = None,
) -> Agreement:
    """How a and b agree; ``ties`` (a pixel mask) are left out with the occlusion edges."""
    both = a.hit & b.hit
    t = b.depth[both]
    dt = np.abs(a.depth[both] - t)
    cos = np.clip((a.normal * b.normal).sum(-1)[both], -1.0, 1.0)
    angle = np.degrees(np.arccos(cos))
    n = max(int(both.sum()), 1)
    off = ~(edges(a) | edges(b) | (False if ties is None else ties))
    rel = np.abs(a.depth - b.depth) / np.maximum(b.depth, 1e-300)
    both_off = both & off
    return Agreement(
        off_edge_hit=int((off & (a.hit != b.hit)).sum()),
        off_edge_depth=float(rel[both_off].max()) if both_off.any() else 0.0,
        off_edge_color=float(np.abs(a.color - b.color).max(-1)[off].max()) if off.any() else 0.0,
        hit=float((a.hit == b.hit).mean()),
        depth_close=float((dt <= depth_rel * np.maximum(t, 1e-12)).sum() / n)
        if both.any()
        else 1.0,
        normal_close=float((angle <= normal_deg).sum() / n) if both.any() else 1.0,
        color=float((np.abs(a.color - b.color).max(-1) <= color_tol).mean()),
    )


# Tolerances of the GPU (float32) against the reference (float64), and why; the pixel tests
# and the stability invariants use these. The fractions hold for the whole image; away from
# occlusion edges (:func:`edges`) every pixel must also meet OFF_EDGE_* below:
HIT_AGREEMENT = 0.995  # a ray whose last distance lands within float32 rounding of ε flips
DEPTH_REL = 1e-3  # same stopping step ⇒ depths agree to float32 accumulation over ~100 steps
NORMAL_DEG = 2.0  # same winning kernel ⇒ same analytic gradient up to float32 rounding
CLOSE_FRACTION = 0.995  # …except where one side stopped a step later (|Δt| ≈ ε(t)) or slipped
# past an outline onto a surface behind
COLOR_TOL = 2.0 / 255.0  # one rounding of each channel plus float32 shading error
COLOR_FRACTION = 0.99
# Away from occlusion edges, the worst pixel: equal hit state, and at most one tracer step
# apart — a step is ≤ ε(t) = footprint × t, under 2 % of t at the tests' image sizes — with
# the colour that small move gives (5/255):
OFF_EDGE_DEPTH = 0.02
OFF_EDGE_COLOR = 5.0 / 255.0


def gpu_reference_agreement(gpu: Frame, ref: Frame, ties: np.ndarray | None = None) -> Agreement:
    return agreement(gpu, ref, DEPTH_REL, NORMAL_DEG, COLOR_TOL, ties)


def tolerance_failures(a: Agreement) -> list[str]:
    """What falls short of the GPU-vs-reference tolerances; empty when all hold."""
    out = []
    if a.off_edge_hit or a.off_edge_depth > OFF_EDGE_DEPTH or a.off_edge_color > OFF_EDGE_COLOR:
        out.append(
            f"away from outlines every pixel must agree: {a.off_edge_hit} hit "
            f"mismatches, depth error up to {a.off_edge_depth:.2g} (≤ {OFF_EDGE_DEPTH}), "
            f"colour error up to {a.off_edge_color:.3f} (≤ {OFF_EDGE_COLOR})"
        )
    if a.hit < HIT_AGREEMENT:
        out.append(f"hit masks agree on {a.hit:.4%} < {HIT_AGREEMENT:.1%}")
    if a.depth_close < CLOSE_FRACTION:
        out.append(f"depth within {DEPTH_REL} on {a.depth_close:.4%} < {CLOSE_FRACTION:.1%}")
    if a.normal_close < CLOSE_FRACTION:
        out.append(f"normals within {NORMAL_DEG}° on {a.normal_close:.4%}")
    if a.color < COLOR_FRACTION:
        out.append(f"colour within 2/255 on {a.color:.4%} < {COLOR_FRACTION:.0%}")
    return out
