"""The numpy pose: axis-angle and matrices convert both ways, and a head turned about a pivot leaves the pivot still."""
import numpy as np

from talkingface.geometry.pose import apply_pose, euler_to_matrix, matrix_to_rotvec, pose_about_pivot, rotvec_to_matrix


def test_rotvec_and_matrix_round_trip():
    rv = np.random.default_rng(0).standard_normal((50, 3)) * 0.8
    R = rotvec_to_matrix(rv)
    np.testing.assert_allclose(R @ R.transpose(0, 2, 1), np.broadcast_to(np.eye(3), R.shape), atol=1e-12)
    np.testing.assert_allclose(matrix_to_rotvec(R), rv, atol=1e-9)
    np.testing.assert_allclose(rotvec_to_matrix(matrix_to_rotvec(euler_to_matrix(rv * 20))), euler_to_matrix(rv * 20), atol=1e-9)


def test_a_pose_about_a_pivot_keeps_the_pivot_still():
    angles = np.random.default_rng(1).uniform(-12, 12, (30, 3))   # degrees, as the corpus's head pose
    pivot = np.array([0.5, -3.0, -8.0])
    pose = pose_about_pivot(angles, pivot)
    moved = apply_pose(np.broadcast_to(pivot, (30, 1, 3)), pose)
    np.testing.assert_allclose(moved[:, 0], np.broadcast_to(pivot, (30, 3)), atol=1e-12)
