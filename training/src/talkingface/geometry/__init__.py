"""Geometry every stage shares: the rigid head pose y = R (I + O) + t (paper Eq. 2) on numpy arrays
(pose.py: the corpus, the metrics) and on tensors (pose_torch.py: the model, the loss), and the opening
between two facing contours (contours.py: lips, eyelids). Nothing here imports torch but pose_torch.py."""
