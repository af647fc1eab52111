"""Rigid head pose on numpy arrays: y = T_p (I + O) = R (I + O) + t (Eq. 2), with the rotation as an
axis-angle vector (radians) and t in the data's units. pose_torch.py is the same maths on tensors."""
from __future__ import annotations

import numpy as np


def rotvec_to_matrix(rv: np.ndarray) -> np.ndarray:
    """(F, 3) axis-angle (radians) -> (F, 3, 3), Rodrigues' formula."""
    angle = np.linalg.norm(rv, axis=1)
    k = rv / np.maximum(angle, 1e-12)[:, None]
    K = np.zeros((len(rv), 3, 3))
    K[:, 0, 1], K[:, 0, 2], K[:, 1, 2] = -k[:, 2], k[:, 1], -k[:, 0]
    K = K - K.transpose(0, 2, 1)
    s, c = np.sin(angle)[:, None, None], np.cos(angle)[:, None, None]
    return np.eye(3)[None] + s * K + (1 - c) * (K @ K)


def matrix_to_rotvec(R: np.ndarray) -> np.ndarray:
    """(F, 3, 3) rotations -> (F, 3) axis-angle vectors (radians); valid for angles below pi."""
    cos = np.clip((np.trace(R, axis1=1, axis2=2) - 1) / 2, -1, 1)
    angle = np.arccos(cos)
    axis = np.stack([R[:, 2, 1] - R[:, 1, 2], R[:, 0, 2] - R[:, 2, 0], R[:, 1, 0] - R[:, 0, 1]], 1)
    s = np.sin(angle)
    small = s < 1e-8
    factor = np.where(small, 0.5, angle / (2 * np.where(small, 1.0, s)))
    return axis * factor[:, None]


def euler_to_matrix(angles_deg: np.ndarray) -> np.ndarray:
    """(F, 3) degrees (x, y, z applied in that order: R = Rz Ry Rx) -> (F, 3, 3)."""
    ax, ay, az = np.radians(angles_deg).T
    cx, sx, cy, sy, cz, sz = np.cos(ax), np.sin(ax), np.cos(ay), np.sin(ay), np.cos(az), np.sin(az)
    one, zero = np.ones_like(ax), np.zeros_like(ax)
    Rx = np.stack([one, zero, zero, zero, cx, -sx, zero, sx, cx], 1).reshape(-1, 3, 3)
    Ry = np.stack([cy, zero, sy, zero, one, zero, -sy, zero, cy], 1).reshape(-1, 3, 3)
    Rz = np.stack([cz, -sz, zero, sz, cz, zero, zero, zero, one], 1).reshape(-1, 3, 3)
    return Rz @ Ry @ Rx


def pose_about_pivot(angles_deg: np.ndarray, pivot: np.ndarray) -> np.ndarray:
    """(F, 3) Euler degrees turning the head about `pivot` -> (F, 6) [rotvec (rad), translation], y = R x + t."""
    R = euler_to_matrix(angles_deg)
    t = pivot[None, :] - (R @ pivot)
    return np.concatenate([matrix_to_rotvec(R), t], 1)


def apply_pose(vertices: np.ndarray, pose: np.ndarray) -> np.ndarray:
    """(F, N, 3) unposed I + O and (F, 6) poses -> posed y = T_p (I + O) (Eq. 2)."""
    R = rotvec_to_matrix(pose[:, :3])
    return np.einsum("fij,fnj->fni", R, vertices) + pose[:, None, 3:]


def pose_degrees(pose: np.ndarray) -> np.ndarray:
    """(F, 6) -> (F,) rotation angle from the neutral pose, degrees."""
    return np.degrees(np.linalg.norm(pose[:, :3], axis=1))


def pose_step_degrees(pose: np.ndarray) -> np.ndarray:
    """(F, 6) -> (F-1,) rotation between consecutive frames, degrees (small angles: the axis-angle difference)."""
    return np.degrees(np.linalg.norm(np.diff(pose[:, :3], axis=0), axis=1))
