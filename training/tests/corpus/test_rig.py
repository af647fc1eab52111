"""The rig reads only regions and the mesh graph."""
import dataclasses

import numpy as np

from talkingface.corpus.coarticulation import articulation_track, segments_from_pairs
from talkingface.corpus.rig import Rig
from talkingface.geometry.contours import contour_gap
from talkingface.template import subdivide


def test_rig_works_on_another_topology_and_unit(template):
    """The rig reads only regions and the mesh graph: a subdivided face in millimetres closes and opens alike."""
    base = template
    fine = subdivide(base)
    fine = dataclasses.replace(fine, vertices=fine.vertices * 10.0, units="mm")
    assert fine.num_vertices == base.num_vertices + len(base.edges()) // 2  # one new vertex per edge
    segs = segments_from_pairs([("SIL", 0, 0.3), ("AA", 0.3, 0.55), ("M", 0.55, 0.65), ("AA", 0.65, 0.9), ("SIL", 0.9, 1.2)])
    params = articulation_track(segs, 36, 30)
    frames = Rig(fine).deform(params, np.zeros(36), np.zeros(36))
    r = fine.regions
    gap = contour_gap(frames, r["lips_inner_upper"], r["lips_inner_lower"])  # mm
    assert gap[18] < 0.5          # /m/ at 0.6 s
    assert gap[13] > 5.0          # /aa/ at 0.43 s
