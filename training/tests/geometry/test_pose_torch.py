"""The tensor pose: Rodrigues and Eq. 2 on known cases, and equal to the numpy pose (geometry/pose.py) on random
poses, large rotations and ones near zero, where the tensor form switches to its Taylor series."""
import numpy as np
import pytest
import torch

from talkingface.geometry import pose as pose_np
from talkingface.geometry.pose_torch import apply_pose, rotvec_to_matrix


def test_pose_geometry():
    rv = torch.tensor([[0.0, 0.0, np.pi / 2]])
    R = rotvec_to_matrix(rv)[0]
    torch.testing.assert_close(R @ torch.tensor([1.0, 0, 0]), torch.tensor([0.0, 1, 0]), atol=1e-6, rtol=0)
    v = torch.randn(4, 10, 3)
    pose = torch.cat([torch.zeros(4, 3), torch.ones(4, 3)], -1)
    torch.testing.assert_close(apply_pose(v, pose), v + 1)


@pytest.mark.parametrize("scale", [1e-5, 1e-3, 0.3, 2.5])  # radians: below and above the Taylor switch (theta^2 < 1e-6)
def test_the_tensor_pose_equals_the_numpy_pose(scale):
    rng = np.random.default_rng(0)
    rv = rng.standard_normal((64, 3)) * scale
    vertices = rng.standard_normal((64, 20, 3)) * 50.0                     # mm
    pose = np.concatenate([rv, rng.standard_normal((64, 3)) * 10.0], 1)
    np.testing.assert_allclose(rotvec_to_matrix(torch.from_numpy(rv)).numpy(), pose_np.rotvec_to_matrix(rv), atol=1e-12, rtol=0)
    posed = apply_pose(torch.from_numpy(vertices), torch.from_numpy(pose)).numpy()
    np.testing.assert_allclose(posed, pose_np.apply_pose(vertices, pose), atol=1e-9, rtol=0)
    # And in float32, as the model runs it: within float32 rounding of positions of a few centimetres.
    posed32 = apply_pose(torch.from_numpy(vertices).float(), torch.from_numpy(pose).float()).numpy()
    np.testing.assert_allclose(posed32, pose_np.apply_pose(vertices, pose), atol=1e-4, rtol=0)
