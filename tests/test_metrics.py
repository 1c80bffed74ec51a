"""Accuracy metrics on constructed images whose answers are known by hand."""

from __future__ import annotations

import math

import numpy as np

from krsview.bench.metrics import compare, error_image, psnr, silhouette, ssim
from krsview.frame import Frame

H, W = 40, 60


def disc(cx: float, cy: float, r: float, depth: float = 5.0) -> Frame:
    y, x = np.mgrid[0:H, 0:W] + 0.5
    hit = (x - cx) ** 2 + (y - cy) ** 2 <= r * r
    color = np.where(hit[..., None], [0.8, 0.4, 0.2], [0.2, 0.3, 0.9])
    normal = np.where(hit[..., None], [0.0, 0.0, -1.0], 0.0)
    return Frame(
        color.astype(float),
        np.where(hit, depth, 0.0),
        normal.astype(float),
        np.full((H, W), 10),
        hit,
    )


def test_identical_images_have_no_error():
    a = disc(30, 20, 10)
    e = compare(a, a, eps_per_t=1e-3, cap=64)
    assert e.holes == e.false_hits == e.depth_eps_p99 == e.normal_deg_p99 == 0
    assert e.psnr == math.inf and math.isclose(e.ssim, 1.0)


def test_a_disc_shifted_by_one_pixel_has_holes_and_false_hits_only_on_its_silhouette():
    truth, image = disc(30, 20, 10), disc(31, 20, 10)
    e = compare(image, truth, eps_per_t=1e-3, cap=64)
    holes = (truth.hit & ~image.hit).sum()
    false = (image.hit & ~truth.hit).sum()
    assert holes == false > 0  # a shift loses as much as it gains
    assert math.isclose(e.holes, holes / (H * W)) and math.isclose(e.false_hits, false / (H * W))
    assert e.holes_off_silhouette == 0 and e.false_hits_off_silhouette == 0
    assert e.ssim < 1.0 and e.psnr < 40


def test_a_hole_inside_the_disc_is_counted_off_the_silhouette():
    truth = disc(30, 20, 10)
    image = disc(30, 20, 10)
    image.hit[18:21, 28:32] = False  # a 3×4 hole well inside
    e = compare(image, truth, eps_per_t=1e-3, cap=64)
    assert e.holes * H * W == 12 and e.holes_off_silhouette * H * W == 12
    assert e.false_hits == 0
    pic = error_image(image, truth)
    assert (pic == (255, 40, 40)).all(-1).sum() == 12


def test_depth_error_is_in_units_of_epsilon():
    truth, image = disc(30, 20, 10, depth=5.0), disc(30, 20, 10, depth=5.01)
    e = compare(image, truth, eps_per_t=1e-3, cap=64)  # ε(5) = 0.005: off by 2 ε
    assert math.isclose(e.depth_eps_median, 2.0, rel_tol=1e-9)


def test_capped_rays_are_counted():
    image = disc(30, 20, 10)
    image.iterations[:, :5] = 64  # a band of misses that spent the cap
    e = compare(image, image, eps_per_t=1e-3, cap=64)
    assert math.isclose(e.capped, 5 / W)


def test_psnr_and_ssim_of_known_images():
    a = np.zeros((H, W, 3))
    b = np.full((H, W, 3), 0.1)
    assert math.isclose(psnr(a, b), 20.0)  # mse 0.01 → 20 dB
    rng = np.random.default_rng(0)
    noise = np.clip(a + rng.normal(0, 0.2, a.shape), 0, 1)
    assert ssim(a, noise) < 0.5 < ssim(a, a + 1e-3)


def test_silhouette_marks_both_sides_of_an_outline():
    hit = np.zeros((5, 5), bool)
    hit[:, 3:] = True
    s = silhouette(hit)
    assert s[:, 2:4].all() and not s[:, [0, 1, 4]].any()
