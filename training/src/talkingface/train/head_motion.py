"""Measures of head motion that a still head cannot satisfy (issue 15).

Head motion is one-to-many: a regression onto it converges to the mean, a head that barely moves, and the
pose error (an angle to the truth, frame by frame) rewards exactly that. What a viewer notices is how much the
head moves and whether it moves with the speech:

- spread: the standard deviation of each rotation axis within a clip, predicted / true (per axis and in all);
- the distribution of head movement (the paper's Fig. 4): angular speed per frame, predicted against true, with
  their 1-D Wasserstein distance and a histogram plot;
- following speech: the correlation, within each clip, of the head's angular speed with the speech envelope
  (mean log-Mel energy), predicted and true;
- jitter (the mean second difference) against the truth's.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..geometry.pose import pose_step_degrees
from .metrics import jitter_deg
from .subsets import labels

AXES = ("pitch", "yaw", "roll")  # rotation about x, y, z (axis-angle components, template axes)


def envelope(mel: np.ndarray, mel_index: np.ndarray) -> np.ndarray:
    """Speech loudness per frame: the mean log-Mel band at each frame's Mel position."""
    return mel[np.clip(mel_index, 0, len(mel) - 1)].mean(1)


def _corr(a: np.ndarray, b: np.ndarray) -> float:
    n = min(len(a), len(b))
    a, b = a[:n], b[:n]
    return float(np.corrcoef(a, b)[0, 1]) if n > 2 and a.std() > 1e-9 and b.std() > 1e-9 else 0.0


def clip_head_motion(true_pose: np.ndarray, pred_pose: np.ndarray, env: np.ndarray) -> dict:
    n = min(len(true_pose), len(pred_pose))
    t, p = true_pose[:n], pred_pose[:n]
    speed_t, speed_p = pose_step_degrees(t), pose_step_degrees(p)
    # Envelope change between the same consecutive frames: the head moves on stressed, loud syllables.
    loud = np.abs(np.diff(env[:n])) + 0.5 * (env[1:n] - env[:n].mean())
    return {"std_true": np.degrees(t[:, :3].std(0)).tolist(), "std_pred": np.degrees(p[:, :3].std(0)).tolist(),
            "speed_true": speed_t, "speed_pred": speed_p,
            "follow_true": _corr(speed_t, loud), "follow_pred": _corr(speed_p, loud),
            "jitter_true": jitter_deg(t), "jitter_pred": jitter_deg(p)}


def wasserstein_1d(a: np.ndarray, b: np.ndarray, points: int = 200) -> float:
    q = np.linspace(0, 1, points)
    return float(np.mean(np.abs(np.quantile(a, q) - np.quantile(b, q))))


def summarise(rows: list[dict]) -> dict | None:
    if not rows:
        return None
    st, sp = np.array([r["std_true"] for r in rows]), np.array([r["std_pred"] for r in rows])  # (clips, 3)
    speed_t = np.concatenate([r["speed_true"] for r in rows])
    speed_p = np.concatenate([r["speed_pred"] for r in rows])
    ft, fp = float(np.mean([r["follow_true"] for r in rows])), float(np.mean([r["follow_pred"] for r in rows]))
    return {"spread_true_deg": float(np.linalg.norm(st.mean(0))), "spread_pred_deg": float(np.linalg.norm(sp.mean(0))),
            "spread_ratio": float(np.linalg.norm(sp.mean(0)) / max(np.linalg.norm(st.mean(0)), 1e-9)),
            "spread_ratio_axes": {a: float(sp[:, i].mean() / max(st[:, i].mean(), 1e-9)) for i, a in enumerate(AXES)},
            "speed_true_mean_deg": float(speed_t.mean()), "speed_pred_mean_deg": float(speed_p.mean()),
            "speed_wasserstein_deg": wasserstein_1d(speed_t, speed_p),
            "follow_true": ft, "follow_pred": fp, "follow_ratio": fp / ft if abs(ft) > 1e-9 else 0.0,
            "jitter_true_deg": float(np.mean([r["jitter_true"] for r in rows])),
            "jitter_pred_deg": float(np.mean([r["jitter_pred"] for r in rows]))}


def plot_speed_histogram(rows: list[dict], path: Path, title: str) -> None:
    """The paper's Fig. 4: how often the head moves how fast, the truth against the model."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    t = np.concatenate([r["speed_true"] for r in rows])
    p = np.concatenate([r["speed_pred"] for r in rows])
    bins = np.linspace(0, max(np.quantile(t, 0.99), np.quantile(p, 0.99), 1e-3), 40)
    fig, ax = plt.subplots(figsize=(6, 3.2), dpi=110)
    ax.hist(np.clip(t, 0, bins[-1]), bins, alpha=0.6, label="truth", density=True)
    ax.hist(np.clip(p, 0, bins[-1]), bins, alpha=0.6, label="model", density=True)
    ax.set_xlabel("head rotation per frame (degrees)")
    ax.set_ylabel("density")
    ax.set_title(title, fontsize=9)
    ax.legend()
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path)
    plt.close(fig)


def sampled_note(sampled: dict) -> str:
    draws = sampled.get("draws", 1)
    return (f"Predicted: the pose head's mean pose plus the head's own motion (model/head_motion.py), test clip i's first draw "
            f"with seed {sampled['seed']} + i" + (f", and {draws - 1} more per clip (`--head-draws {draws}`): the spread, speed, W1 "
            "follows-speech and jitter figures average them, and \"one draw's spread ratio\" is the range of the ratio over the "
            "draws taken one at a time (what a single seed per clip could report); the paper's metrics take the first draw"
            if draws > 1 else "") + ". `--mean-pose` measures the mean alone (spread ratio 0.11 before the head's own motion).")


def fit_note(fit: dict | None) -> str:
    """How the checkpoint's head motion was fitted (model.head_motion records it), in words; empty when not recorded."""
    if not fit:
        return ""
    origin = "from the model's mean pose (`--against-mean`)" if fit["against_mean"] else "from the neutral pose"
    readout = f"speech read-out ridge {fit['ridge']:g}" if fit.get("ridge") is not None else "no speech read-out"
    return f" Fitted on the {fit['split']} split, residuals {origin}, {readout}, gain on the {fit['gain']}."


def summarise_draws(rows: list[dict]) -> dict | None:
    """summarise() over every draw's rows (each clip counted once per draw: the measures' expectation over draws), with
    the spread ratio of each draw on its own ("spread_ratio_draws": how far one draw per clip can land from it)."""
    out = summarise(rows)
    if out is not None:
        draws = sorted({r.get("draw", 0) for r in rows})
        out["spread_ratio_draws"] = [summarise([r for r in rows if r.get("draw", 0) == k])["spread_ratio"] for k in draws]
    return out


def markdown(res: dict, plot_name: str) -> list[str]:
    rows = []
    for name, label in labels(res.get("split", "test")):
        h = res["head_motion"].get(name)
        if h:
            ax, each = h["spread_ratio_axes"], h.get("spread_ratio_draws") or []
            spread_range = f"{min(each):.2f} - {max(each):.2f}" if len(each) > 1 else "-"
            rows.append(f"| {label} | {h['spread_true_deg']:.2f} / {h['spread_pred_deg']:.2f} | **{h['spread_ratio']:.2f}** "
                        f"({ax['pitch']:.2f} / {ax['yaw']:.2f} / {ax['roll']:.2f}) | {spread_range} | {h['speed_true_mean_deg']:.3f} / "
                        f"{h['speed_pred_mean_deg']:.3f} | {h['speed_wasserstein_deg']:.3f} | {h['follow_true']:.2f} / "
                        f"{h['follow_pred']:.2f} | {h['jitter_true_deg']:.3f} / {h['jitter_pred_deg']:.3f} |")
    return [
        "## Head motion",
        "",
        "Spread: standard deviation of the head rotation within a clip (degrees, the three axes' norm), true / predicted,",
        "and their ratio (per axis: pitch / yaw / roll). Speed: rotation per frame; W1: the 1-D Wasserstein distance",
        "between the true and predicted speed distributions (degrees). Follows speech: correlation within a clip of",
        "the head's speed with the speech envelope's change, true / predicted. Jitter: true / predicted.",
        "",
        *([sampled_note(res["head_motion"]["sampled"]) + fit_note(res["head_motion"].get("fit")), ""]
          if res["head_motion"].get("sampled") else ["Predicted: the pose head's mean pose alone.", ""]),
        "| clips | spread (deg) | spread ratio (pitch / yaw / roll) | one draw's spread ratio | speed (deg/frame) | speed W1 | follows speech | jitter (deg) |",
        "| --- | --- | --- | --- | --- | --- | --- | --- |",
        *rows,
        "",
        f"![head movement distribution, truth against model (the paper's Fig. 4)]({plot_name})",
        "",
    ]
