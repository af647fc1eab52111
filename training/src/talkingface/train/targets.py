"""Issues 14 and 15's targets against an evaluation (evaluate.py's results): which are met, on all clips and on
recorded speech, each. docs/results/default.md shows them under its tables; default.json holds them as "targets".

The targets are the issues' own words (docs/results/README.md quotes them); E_vl and E_ve compare with the model
before issue 14 (docs/results/budget/LG-GAVA-50min-before-frontend.md, the same test split).
"""
from __future__ import annotations

from .articulation import CLOSED_MM

E_VL_BEFORE_MM, E_VE_BEFORE_MM = 3.570, 0.195   # the model before issue 14, test split


def _ratio(r: dict, num: str, den: str) -> float | None:
    return r[num] / r[den] if r and r.get(den) else None


def measures(res: dict, part: str) -> list[tuple[int, str, float | None, str, bool | None]]:
    """(issue, measure, value, target, met) for the clips `part` ("all" or "human") names."""
    a, c, h, m = (res["articulation"].get(part), res["content_encoder"].get(part), res["head_motion"].get(part), res.get(part))
    rows = []

    def row(issue: int, name: str, value, target: str, test) -> None:
        rows.append((issue, name, value, target, None if value is None else bool(test(value))))

    row(14, "content encoder frame accuracy", c and c["frame_accuracy"], ">= 70%", lambda v: v >= 0.70)
    row(14, "/p b m/ segments heard as bilabial", c and c["bilabial_segments_heard"], ">= 90%", lambda v: v >= 0.90)
    row(14, "/p b m/ closed", a and a["pred_closure"], ">= 95%", lambda v: v >= 0.95)
    row(14, "open vowels opened", a and a["pred_open_vowel_opened"], ">= 95%", lambda v: v >= 0.95)
    row(14, "inner-lip gap correlation", a and a["gap_corr"], ">= 0.85", lambda v: v >= 0.85)
    row(14, "lip amplitude ratio", _ratio(m, "lip_motion_pred", "lip_motion_gt"), "0.9 - 1.1", lambda v: 0.9 <= v <= 1.1)
    if part == "all":
        row(14, "silence: mean inner-lip gap (mm)", res["silence"]["lip_gap_mean_mm"], f"< {CLOSED_MM:g} (closed)", lambda v: v < CLOSED_MM)
        row(14, "E_vl (mm)", m["E_vl"], f"< {E_VL_BEFORE_MM:.3f} (before)", lambda v: v < E_VL_BEFORE_MM)
        row(14, "E_ve (mm)", m["E_ve"], f"<= {E_VE_BEFORE_MM:.3f} (before)", lambda v: round(v, 3) <= E_VE_BEFORE_MM)
    row(15, "head rotation spread ratio", h and h["spread_ratio"], "0.8 - 1.25", lambda v: 0.8 <= v <= 1.25)
    follow = (h["follow_pred"] / h["follow_true"]) if h and h["follow_true"] > 0 else None
    row(15, "follows speech, against the truth", follow, ">= 0.5", lambda v: v >= 0.5)
    row(15, "jitter, against the truth's", _ratio(m, "pose_jitter_deg", "pose_jitter_gt_deg"), "0.5 - 2", lambda v: 0.5 <= v <= 2)
    return rows


def check(res: dict) -> dict:
    """{"all": [...], "human": [...]}: each target as {"issue", "measure", "value", "target", "met"}."""
    keys = ("issue", "measure", "value", "target", "met")
    return {part: [dict(zip(keys, r)) for r in measures(res, part)] for part in ("all", "human") if res.get(part)}


def markdown(res: dict) -> list[str]:
    """The targets section of default.md: one row per target, all clips and recorded speech side by side."""
    checked = check(res)
    if "all" not in checked:
        return []
    human = {r["measure"]: r for r in checked.get("human", [])}

    def cell(r: dict | None) -> str:
        if r is None or r["value"] is None:
            return "-"
        v = r["value"]
        text = f"{100 * v:.1f}%" if r["target"].endswith("%") else f"{v:.3f}" if "mm" in r["measure"] else f"{v:.2f}"
        return f"{text} {'met' if r['met'] else '**not met**'}"

    lines = ["## Issue targets", "",
             "Issues 14 (articulation) and 15 (head motion), on all clips and on the recorded speech, each; E_vl and E_ve",
             f"against the model before issue 14 ({E_VL_BEFORE_MM:.3f} / {E_VE_BEFORE_MM:.3f} mm on this split). Follows speech and jitter:",
             "the model's figure divided by the truth's.", "",
             "| issue | measure | target | all clips | recorded speech |", "| --- | --- | --- | --- | --- |"]
    for r in checked["all"]:
        lines.append(f"| {r['issue']} | {r['measure']} | {r['target']} | {cell(r)} | {cell(human.get(r['measure']))} |")
    met = sum(bool(r["met"]) for part in checked.values() for r in part)
    total = sum(r["met"] is not None for part in checked.values() for r in part)
    return [*lines, "", f"{met} of {total} met.", ""]
