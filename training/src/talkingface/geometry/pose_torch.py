"""Rigid head pose on tensors: y = T_p (I + O) = R (I + O) + t (Eq. 2). The same maths as pose.py (numpy),
tested equal to it; this one is differentiable at zero rotation, which the model starts from."""
from __future__ import annotations

import torch


def rotvec_to_matrix(rv: torch.Tensor) -> torch.Tensor:
    """(..., 3) axis-angle (radians) -> (..., 3, 3), Rodrigues; smooth at zero."""
    theta2 = (rv * rv).sum(-1, keepdim=True)                                  # (..., 1)
    theta = torch.sqrt(theta2 + 1e-12)
    # sin(t)/t and (1 - cos t)/t^2 with their Taylor series near 0, so gradients stay finite.
    small = theta2 < 1e-6
    a = torch.where(small, 1 - theta2 / 6, torch.sin(theta) / theta)
    b = torch.where(small, 0.5 - theta2 / 24, (1 - torch.cos(theta)) / (theta2 + 1e-12))
    x, y, z = rv.unbind(-1)
    zero = torch.zeros_like(x)
    K = torch.stack([zero, -z, y, z, zero, -x, -y, x, zero], -1).reshape(*rv.shape[:-1], 3, 3)
    eye = torch.eye(3, dtype=rv.dtype, device=rv.device).expand_as(K)
    return eye + a[..., None] * K + b[..., None] * (K @ K)


def apply_pose(vertices: torch.Tensor, pose: torch.Tensor) -> torch.Tensor:
    """(..., N, 3) unposed I + O and (..., 6) [axis-angle, translation] -> posed (..., N, 3)."""
    R = rotvec_to_matrix(pose[..., :3])                                       # (..., 3, 3)
    return vertices @ R.transpose(-1, -2) + pose[..., None, 3:]
