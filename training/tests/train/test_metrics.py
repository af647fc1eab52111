"""The paper's metrics (Eq. 8-10) and the pose error on errors of known size."""
import numpy as np
import pytest

from talkingface.train import metrics


def test_metrics_on_known_errors(template):
    T, n = 4, template.num_vertices
    gt = np.zeros((T, n, 3))
    pred = gt.copy()
    lips = metrics.lip_region(template)
    assert set(template.regions["lips_outer"]) <= set(lips) and len(lips) > len(template.regions["lips_outer"])
    pred[:, lips[0], 1] = 2.0
    pred[1, lips[1], 1] = 5.0
    assert metrics.max_region_error(gt, pred, lips) == pytest.approx((2 + 5 + 2 + 2) / 4)
    up = template.regions["upper_face"]
    motion_gt = np.zeros((T, n, 3))
    motion_gt[:, up, 0] = np.array([0, 1, 0, 1])[:, None]  # std 0.5 on x
    assert metrics.fdd(motion_gt, np.zeros_like(motion_gt), up) == pytest.approx(0.5)
    assert metrics.afdd(motion_gt, np.zeros_like(motion_gt), up) == pytest.approx(0.5 / 3)
    assert metrics.afdd(motion_gt, -motion_gt, up) == pytest.approx(0.0)
    pose = np.zeros((5, 6))
    pose2 = pose.copy()
    pose2[:, 1] = np.radians(3)
    assert metrics.rotation_angle_deg(pose, pose2) == pytest.approx(np.full(5, 3.0))
