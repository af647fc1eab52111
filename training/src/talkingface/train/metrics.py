"""The paper's metrics (Sec. IV, Eq. 8-10), on one clip's (T, N, 3) arrays in mm.

E_vl / E_ve: mean over frames of the largest lip / eye vertex error (Eq. 8), on the unposed face
I + O, as the paper's "zero pose" comparison; E_vl_posed adds the head pose. FDD (CodeTalker, Eq. 9):
per upper-face vertex, the standard deviation over time of its motion's L2 norm, ground truth minus
prediction, averaged (signed). AFDD (Eq. 10): the same per axis, absolute, averaged over vertices and
axes. Pose error: angle between the true and predicted head rotations; pose jitter: mean size of
the predicted rotation's second difference.
"""
from __future__ import annotations

import numpy as np

from ..geometry.pose import rotvec_to_matrix
from ..template import Template


def lip_region(t: Template) -> np.ndarray:
    """The lip surface: flood the 1-ring graph from the inner-lip contour out to the outer-lip contour."""
    r = t.regions
    outer = set(r["lips_outer"].tolist())
    seen = set(np.concatenate([r["lips_inner_upper"], r["lips_inner_lower"]]).tolist())
    stack = list(seen)
    while stack:
        v = stack.pop()
        if v in outer:
            continue
        for w in t.neighbours(v):
            if int(w) not in seen:
                seen.add(int(w))
                stack.append(int(w))
    return np.array(sorted(seen))


def inner_lip_pairs(t: Template) -> np.ndarray:
    """(P, 2) facing (upper, lower) inner-lip vertices: each upper vertex away from the shared mouth corners,
    with the lower-contour vertex nearest to it across the mouth (in x) on the template."""
    r = t.regions
    upper = np.setdiff1d(r["lips_inner_upper"], r["lips_inner_lower"])
    lower = np.setdiff1d(r["lips_inner_lower"], r["lips_inner_upper"])
    x = t.vertices[:, 0]
    return np.array([[u, lower[np.argmin(np.abs(x[lower] - x[u]))]] for u in upper], dtype=np.int64)


def eye_region(t: Template) -> np.ndarray:
    r = t.regions
    return np.unique(np.concatenate([r[f"eye_{s}_{p}"] for s in ("left", "right") for p in ("upper", "lower")]))


def max_region_error(gt: np.ndarray, pred: np.ndarray, region: np.ndarray) -> float:
    """Eq. 8: mean over frames of max over region vertices of ||pred - gt||_2."""
    return float(np.linalg.norm(pred[:, region] - gt[:, region], axis=-1).max(1).mean())


def fdd(motion_gt: np.ndarray, motion_pred: np.ndarray, upper: np.ndarray) -> float:
    """Eq. 9 (signed): motion = vertices - template, (T, N, 3)."""
    dyn = lambda m: np.linalg.norm(m[:, upper], axis=-1).std(0)
    return float(np.mean(dyn(motion_gt) - dyn(motion_pred)))


def afdd(motion_gt: np.ndarray, motion_pred: np.ndarray, upper: np.ndarray) -> float:
    """Eq. 10: per-axis standard deviation over time, absolute difference, mean over vertices and axes."""
    return float(np.mean(np.abs(motion_gt[:, upper].std(0) - motion_pred[:, upper].std(0))))


def rotation_angle_deg(pose_a: np.ndarray, pose_b: np.ndarray) -> np.ndarray:
    """(T, 6) x2 -> (T,) angle of R_a^T R_b in degrees."""
    Ra, Rb = rotvec_to_matrix(pose_a[:, :3].astype(np.float64)), rotvec_to_matrix(pose_b[:, :3].astype(np.float64))
    cos = (np.trace(np.transpose(Ra, (0, 2, 1)) @ Rb, axis1=1, axis2=2) - 1) / 2
    return np.degrees(np.arccos(np.clip(cos, -1, 1)))


def jitter_deg(pose: np.ndarray) -> float:
    if len(pose) < 3:
        return 0.0
    return float(np.degrees(np.linalg.norm(np.diff(pose[:, :3], 2, axis=0), axis=1)).mean())


def lip_motion(unposed: np.ndarray, template_mm: np.ndarray, lips: np.ndarray) -> float:
    """Mean over frames of the largest lip-vertex displacement from the neutral face (how much the mouth moves)."""
    return float(np.linalg.norm(unposed[:, lips] - template_mm[lips], axis=-1).max(1).mean())


def clip_metrics(gt_unposed, pred_unposed, gt_posed, pred_posed, template_mm, gt_pose, pred_pose, regions) -> dict:
    lips, eyes, upper = regions
    return {
        "lip_motion_gt": lip_motion(gt_unposed, template_mm, lips),
        "lip_motion_pred": lip_motion(pred_unposed, template_mm, lips),
        "E_vl": max_region_error(gt_unposed, pred_unposed, lips),
        # The same for a face that never moves: the baseline E_vl must beat.
        "E_vl_still_face": max_region_error(gt_unposed, np.broadcast_to(template_mm, gt_unposed.shape), lips),
        "E_ve": max_region_error(gt_unposed, pred_unposed, eyes),
        "E_vl_posed": max_region_error(gt_posed, pred_posed, lips),
        "FDD": fdd(gt_unposed - template_mm, pred_unposed - template_mm, upper),
        "AFDD": afdd(gt_unposed - template_mm, pred_unposed - template_mm, upper),
        "pose_error_deg": float(rotation_angle_deg(gt_pose, pred_pose).mean()),
        "pose_jitter_deg": jitter_deg(pred_pose),
        "pose_jitter_gt_deg": jitter_deg(gt_pose),
    }
