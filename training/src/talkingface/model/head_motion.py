"""The head's own motion (issue 15): what a regression cannot give, sampled from a learned distribution.

Head motion is one-to-many: the same sentence is said with many head movements, so the pose head, trained to
regress them, predicts their mean, a head that barely moves. This module adds to the predicted (mean) pose a
residual rotation, part of it read from the speech and the rest drawn from a distribution learned from the truth,
conditioned on the paper's pose token:

    residual_t = A f_t + c + r_t                         per axis (rotation vector components, degrees)
    r_t = a1 r_{t-1} + a2 r_{t-2} + s(f_t) z_t
    s(f_t) = g softplus(W f_t + b)                       f_t: the pose encoder's feature at frame t (the pose token)

A f_t + c is the part of the motion the speech carries (nods on loud, stressed syllables, a lift on pitch peaks):
a linear read-out of the pose token fitted by ridge regression to the residuals (truth against the model's mean)
of the train split. The pose head reads the same token but, trained with the paper's tiny pose weight, moves the
head by a tenth of the truth; the read-out is fitted to the truth alone, so it moves the head as much as the speech
explains and no more. r_t is an AR(2) process for what the speech does not carry (the truth's smooth turns, nods
and tilts: its variance and its frame-to-frame correlations, hence its spread, speed distribution and jitter) whose
step size follows the speech through the pose token. The AR coefficients are fitted by least squares to what the
read-out leaves, the step-size layer by maximum likelihood of the AR innovations, and the gain g so that the spread
within a clip of the whole residual (what a viewer sees, and what an AR(2) fitted to one-step predictions gets
wrong) equals the truth's on the train split. z_t comes from a counter-based generator
(hash of seed, frame, axis), so a given seed gives the same motion offline, in chunks and streaming, here and in
the browser (src/pose/head-motion.ts), and a visitor can draw another. The residual turns the head about the
neck pivot: y' = R_r (y - p) + p.

  scripts/py -m talkingface.model.head_motion --corpus data/corpus --checkpoint models/checkpoint.pt

fits the distribution and writes it into the checkpoint (key "head_motion"); export.py ships it.
"""
from __future__ import annotations

import argparse
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..geometry.pose import matrix_to_rotvec, rotvec_to_matrix

MASK32 = 0xFFFFFFFF
# How strongly the step-size layer is held to the mean step (1e-2 gave the same gains on the train split).
WEIGHT_DECAY = 1e-4
# The speech read-out's ridge penalty, per frame (chosen on the val split: 1e-3 follows the speech more but doubles
# the jitter the read-out adds; docs/results/README.md).
SPEECH_RIDGE = 1e-2


def hash32(x: np.ndarray) -> np.ndarray:
    """A 32-bit integer hash (lowbias32, C. Wellons): uint32 -> uint32, well mixed. Same arithmetic as the browser."""
    x = x.astype(np.uint64) & MASK32
    x ^= x >> 16
    x = (x * 0x7FEB352D) & MASK32
    x ^= x >> 15
    x = (x * 0x846CA68B) & MASK32
    x ^= x >> 16
    return x


def normal(seed: int, frame: np.ndarray, axis: int) -> np.ndarray:
    """Standard normal draws for (seed, frame, axis), frames >= -2: Box-Muller on two hashed uniforms in (0, 1)."""
    base = (np.asarray(frame, np.int64) + 2) * 8 + axis * 2 + 1
    key = hash32(hash32(np.uint64((seed + 0x632BE5AB) & MASK32)) ^ hash32(base.astype(np.uint64)))
    u1 = (hash32(key) + 0.5) / 2**32
    u2 = (hash32(key ^ 0x9E3779B9) + 0.5) / 2**32
    return np.sqrt(-2.0 * np.log(u1)) * np.cos(2.0 * np.pi * u2)


@dataclass
class HeadMotion:
    ar: np.ndarray          # (3, 2) a1, a2 per axis
    sigma_w: np.ndarray     # (3, d) step-size layer
    sigma_b: np.ndarray     # (3,)
    sigma_mean: np.ndarray  # (3,) the mean step size over the train split (for the stationary start), gain included
    pivot_mm: np.ndarray    # (3,) where the head turns, on the template (mm)
    gain: np.ndarray        # (3,) g: the truth's spread within a clip over the process's
    speech_w: np.ndarray | None = None  # (3, d) A: the part of the motion the speech carries (None: none)
    speech_b: np.ndarray | None = None  # (3,) c

    def __post_init__(self):
        if self.speech_w is None:
            self.speech_w = np.zeros_like(self.sigma_w)
        if self.speech_b is None:
            self.speech_b = np.zeros(3)

    def to_dict(self) -> dict:
        return {k: np.asarray(v, np.float32).tolist() for k, v in self.__dict__.items()}

    @classmethod
    def from_dict(cls, d: dict) -> "HeadMotion":
        return cls(**{k: np.asarray(v, np.float64) for k, v in d.items()})

    def speech(self, feats: np.ndarray) -> np.ndarray:
        """(F, d) pose-token features -> (F, 3) the part of the motion read from the speech (degrees)."""
        return feats.astype(np.float64) @ self.speech_w.T + self.speech_b

    def steps(self, feats: np.ndarray) -> np.ndarray:
        """(F, d) pose-token features -> (F, 3) step sizes (degrees)."""
        x = feats.astype(np.float64) @ self.sigma_w.T + self.sigma_b
        return self.gain * np.logaddexp(0.0, x)  # g softplus

    def stationary(self) -> tuple[np.ndarray, np.ndarray]:
        """Per axis: the stationary standard deviation at unit step size, and the lag-1 correlation."""
        a1, a2 = self.ar[:, 0], self.ar[:, 1]
        gamma0 = (1 - a2) / ((1 + a2) * ((1 - a2) ** 2 - a1 ** 2))
        return np.sqrt(np.maximum(gamma0, 0.0)), a1 / (1 - a2)

    def sample(self, feats: np.ndarray, seed: int) -> np.ndarray:
        """(F, d) pose-token features -> (F, 3) residual rotation vectors (degrees), drawn with `seed`: the speech's
        part plus the process."""
        return self.speech(feats) + self.process(feats, seed)

    def process(self, feats: np.ndarray, seed: int) -> np.ndarray:
        """(F, d) pose-token features -> (F, 3) the AR(2) process alone (degrees), drawn with `seed`."""
        n = len(feats)
        s = self.steps(feats)
        sd, rho = self.stationary()
        out = np.zeros((n, 3))
        for k in range(3):
            z = normal(seed, np.arange(-2, n), k)
            r2 = self.sigma_mean[k] * sd[k] * z[0]
            r1 = rho[k] * r2 + self.sigma_mean[k] * sd[k] * np.sqrt(max(1 - rho[k] ** 2, 0.0)) * z[1]
            a1, a2 = self.ar[k]
            for t in range(n):
                r = a1 * r1 + a2 * r2 + s[t, k] * z[t + 2]
                out[t, k], r2, r1 = r, r1, r
        return out


def compose(pose: np.ndarray, residual_deg: np.ndarray, pivot: np.ndarray) -> np.ndarray:
    """The predicted poses (F, 6: rotvec rad, translation mm) turned by residual rotations about the pivot:
    y' = R_r (R x + t - p) + p, i.e. R' = R_r R, t' = R_r (t - p) + p."""
    Rr = rotvec_to_matrix(np.radians(residual_deg))
    R = Rr @ rotvec_to_matrix(pose[:, :3].astype(np.float64))
    t = np.einsum("fij,fj->fi", Rr, pose[:, 3:] - pivot) + pivot
    return np.concatenate([matrix_to_rotvec(R), t], 1).astype(np.float32)


def residual_of(true_pose: np.ndarray, pred_pose: np.ndarray) -> np.ndarray:
    """The rotation taking the predicted head to the true one, R_t R_p^T, as rotation vectors in degrees."""
    R = rotvec_to_matrix(true_pose[:, :3].astype(np.float64)) @ rotvec_to_matrix(pred_pose[:, :3].astype(np.float64)).transpose(0, 2, 1)
    return np.degrees(matrix_to_rotvec(R))


def fit_ar2(series: list[np.ndarray]) -> tuple[np.ndarray, list[np.ndarray]]:
    """Per axis least squares r_t ~ a1 r_{t-1} + a2 r_{t-2} over all clips -> (3, 2) and each clip's innovations (F-2, 3)."""
    ar = np.zeros((3, 2))
    for k in range(3):
        X = np.concatenate([np.stack([r[1:-1, k], r[:-2, k]], 1) for r in series])
        y = np.concatenate([r[2:, k] for r in series])
        ar[k] = np.linalg.lstsq(X, y, rcond=None)[0]
    if not all(abs(a2) < 1 and a2 + a1 < 1 and a2 - a1 < 1 for a1, a2 in ar):  # else its spread grows without bound
        raise ValueError(f"the head's fitted AR(2) {ar.round(4).tolist()} does not settle (|a2| < 1, a2 +- a1 < 1 per axis)")
    innov = [r[2:] - r[1:-1] * ar[:, 0] - r[:-2] * ar[:, 1] for r in series]
    return ar, innov


def fit_steps(feats: np.ndarray, innov: np.ndarray, steps: int = 600, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Maximum likelihood of innovations e ~ N(0, softplus(W f + b)^2): (N, d), (N, 3) -> W (3, d), b (3,)."""
    import torch
    torch.manual_seed(seed)
    f = torch.from_numpy(feats).float()
    e = torch.from_numpy(innov).float()
    W = torch.zeros(3, f.shape[1], requires_grad=True)
    b = torch.log(torch.expm1(e.std(0).clamp(min=1e-4))).detach().requires_grad_(True)  # start at the overall step size
    opt = torch.optim.Adam([W, b], lr=0.01)
    for _ in range(steps):
        s = torch.nn.functional.softplus(f @ W.T + b)
        loss = (torch.log(s) + 0.5 * (e / s) ** 2).mean() + WEIGHT_DECAY * (W ** 2).sum()
        opt.zero_grad()
        loss.backward()
        opt.step()
    return W.detach().numpy().astype(np.float64), b.detach().numpy().astype(np.float64)


def clip_features(model, mel: np.ndarray, n_frames: int) -> tuple[np.ndarray, np.ndarray]:
    """The model's predicted (mean) poses (F, 6) and pose-token features (F, d) of one clip."""
    import torch
    from ..features import frame_to_mel_index
    m = torch.from_numpy(mel)
    with torch.no_grad():
        feat, _ = model.pose_encoder(m[None])
    idx = np.minimum(frame_to_mel_index(np.arange(n_frames), model.audio), len(mel) - 1)
    return feat[0, idx].numpy(), idx


def collect(model, ds, split: str = "train", progress=None, against_mean: bool = False) -> tuple[list, list, list[str], list[str]]:
    """Per clip of the split: the residual rotations (degrees), the pose-token features, the speaker and the source
    ("tts" or "human"). The residual is the truth's rotation itself by default (the pose
    head's mean moves the head by about a tenth of the truth, so the two differ little, and this needs only the pose
    encoder); `against_mean`: the rotation from the model's mean pose to the truth (the whole model on every clip)."""
    import torch
    from ..train.data import prepare
    residuals, feats, speakers, sources = [], [], [], []
    keys = ds.keys(split)
    for i, key in enumerate(keys):
        c = prepare(ds, key, model.audio)
        f, _ = clip_features(model, c.mel, c.num_frames)
        mean = model.animate(torch.from_numpy(c.mel), torch.from_numpy(c.template), c.num_frames)["pose"].numpy() \
            if against_mean else np.zeros_like(c.pose)
        if c.num_frames >= 8:
            residuals.append(residual_of(c.pose, mean))
            feats.append(f)
            speakers.append(ds.subject_of(key))
            sources.append(c.source)
        if progress:
            progress(i + 1, len(keys))
    return residuals, feats, speakers, sources


def fit_speech(residuals: list[np.ndarray], feats: list[np.ndarray], ridge: float = SPEECH_RIDGE) -> tuple[np.ndarray, np.ndarray]:
    """Ridge regression of the residuals on the pose-token features over all frames: (3, d) A and (3,) c with
    residual ~ A f + c, the penalty `ridge` per frame on A."""
    X = np.concatenate(feats).astype(np.float64)
    Y = np.concatenate(residuals).astype(np.float64)
    mx, my = X.mean(0), Y.mean(0)
    Xc = X - mx
    A = np.linalg.solve(Xc.T @ Xc + ridge * len(X) * np.eye(X.shape[1]), Xc.T @ (Y - my))  # (d, 3)
    return A.T, my - mx @ A


def fit(residuals: list[np.ndarray], feats: list[np.ndarray], pivot_mm: np.ndarray, ridge: float | None = SPEECH_RIDGE,
        speakers: list[str] | None = None) -> HeadMotion:
    """The residual distribution from collect()'s clips: the speech read-out (`ridge` None: none), AR(2) and the
    step-size layer on what it leaves, then the gain: with `speakers` (one name per clip), so that the geometric mean
    over speakers of the spread ratio (the model's over the truth's) is one; without, so that the spreads' means
    over all clips are equal."""
    A, c = fit_speech(residuals, feats, ridge) if ridge is not None else (np.zeros((3, feats[0].shape[1])), np.zeros(3))
    rest = [r - (f @ A.T + c) for r, f in zip(residuals, feats)]
    ar, innov = fit_ar2(rest)
    F = np.concatenate([f[2:] for f in feats])
    E = np.concatenate(innov)
    W, b = fit_steps(F, E)
    sigma_mean = np.logaddexp(0.0, F @ W.T + b).mean(0)
    head = HeadMotion(ar=ar, sigma_w=W, sigma_b=b, sigma_mean=sigma_mean, pivot_mm=np.asarray(pivot_mm, np.float64),
                      gain=np.ones(3), speech_w=A, speech_b=c)
    # The gain: the whole residual's spread within a clip (the speech's part plus the process) against the truth's,
    # on the same clips (three draws each, every draw its own seed: one seed gives every clip the same draws, and so
    # one sample of the spread, not its mean). Speakers move their heads by very different amounts (the corpus's
    # train speakers by 0.9 to 2.2 deg) that the audio does not carry, so the model can only move like a typical
    # one; the spread is judged as a ratio (issue 15: 0.8-1.25), and the speaker whose ratio errs least on average
    # in those terms is the geometric mean, each speaker counted once. The spread of a sum is not proportional to
    # the process's gain, so a few fixed-point rounds.
    group = np.asarray(speakers if speakers is not None else ["all"] * len(residuals))
    names = sorted(set(group.tolist()))
    true_sd = np.array([r.std(0) for r in residuals])                                  # (clips, 3)
    for _ in range(4):
        pred_sd = np.array([np.mean([head.sample(f, 1000 * k + i).std(0) for k in range(3)], 0) for i, f in enumerate(feats)])
        ratios = np.array([pred_sd[group == g].mean(0) / true_sd[group == g].mean(0) for g in names])  # (speakers, 3)
        head.gain = head.gain / np.exp(np.log(ratios).mean(0))
        head.sigma_mean = sigma_mean * head.gain
    return head


def motion_stats(tracks: list[np.ndarray]) -> dict:
    """(F, 3) rotation tracks (degrees) -> what a viewer sees of them, over the clips: spread (the norm of the per-axis
    standard deviations within a clip, averaged over clips), speed (rotation per frame: mean and 95th percentile)
    and jitter (the mean second difference), the measures of talkingface.train.evaluate on the residual alone."""
    speed = np.concatenate([np.linalg.norm(np.diff(x, axis=0), axis=1) for x in tracks])
    jitter = np.concatenate([np.linalg.norm(np.diff(x, 2, axis=0), axis=1) for x in tracks])
    return {"spread": float(np.mean([np.linalg.norm(x.std(0)) for x in tracks])), "speed": float(speed.mean()),
            "speed_p95": float(np.percentile(speed, 95)), "jitter": float(jitter.mean())}


def main(argv=None) -> int:
    import torch
    from ..cli import check_out_file, dataset_of, dataset_options, made_from, npz_path
    from .residual_cache import cached
    from ..train.train import load_checkpoint
    ap = argparse.ArgumentParser(prog="python -m talkingface.model.head_motion", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--corpus", type=Path, required=True)
    ap.add_argument("--checkpoint", type=Path, required=True, help="read, and written back with the fitted distribution")
    ap.add_argument("--out", type=Path, help="write here instead of back into --checkpoint")
    ap.add_argument("--against-mean", action="store_true", help="fit the residual from the model's mean pose (slow: the whole model on every clip)")
    ap.add_argument("--cache", type=Path, help="keep the train split's residuals and features here (an .npz), and reuse them")
    ap.add_argument("--ridge", type=float, default=SPEECH_RIDGE, help="the speech read-out's ridge penalty per frame (default %(default)s)")
    ap.add_argument("--no-speech", action="store_true", help="no speech read-out: the process alone (the earlier model)")
    ap.add_argument("--per-clip", action="store_true", help="the gain from the spreads' means over all clips (the earlier model), "
                    "not the geometric mean over speakers")
    dataset_options(ap)
    args = ap.parse_args(argv)
    check_out_file(ap, args.out)
    if args.cache:
        check_out_file(ap, args.cache, "--cache")
        args.cache = npz_path(args.cache)  # numpy adds .npz to a name without it: found again by that name
    ds = dataset_of(args)
    model, ck = load_checkpoint(args.checkpoint, ds.template)
    model.eval()

    progress = lambda i, n: (i % 50 == 0 or i == n) and print(f"  {i}/{n} clips", file=sys.stderr)
    source = made_from(args.checkpoint, args.corpus, text="\n".join(ds.keys("train")))  # what the residuals depend on
    residuals, feats, speakers, sources = cached(args.cache, source, args.against_mean,
                                                 lambda: collect(model, ds, "train", progress, args.against_mean))
    from ..corpus.clip import neck_pivot
    template_mm = ds.template.vertices.astype(np.float64) * ds.mm_per_unit
    hm = fit(residuals, feats, neck_pivot(template_mm, ds.template), None if args.no_speech else args.ridge,
             None if args.per_clip else speakers)
    sd, rho = hm.stationary()
    speech = np.concatenate([hm.speech(f) for f in feats])
    print("speech read-out: spread of its part (deg, per axis):", np.round(speech.std(0), 3).tolist(),
          " of the truth's:", np.round(np.concatenate(residuals).std(0), 3).tolist())
    print("AR(2) per axis (pitch, yaw, roll):", np.round(hm.ar, 4).tolist())
    print("gain:", np.round(hm.gain, 3).tolist(), " mean step (deg):", np.round(hm.sigma_mean, 4).tolist(),
          " stationary spread (deg):", np.round(hm.sigma_mean * sd, 3).tolist())
    # What the fit gives on the clips it was fitted to (clip i drawn with seed i): in all, per speaker (speakers move by
    # different amounts that the audio does not carry) and per source (recorded speech against synthetic, same faces).
    drawn = [hm.sample(f, i) for i, f in enumerate(feats)]
    fmt = lambda st: " ".join(f"{k} {v:.3f}" for k, v in st.items())
    print(f"train split, truth: {fmt(motion_stats(residuals))}\n             model: {fmt(motion_stats(drawn))}")
    for names in (speakers, sources):
        for g in sorted(set(names)):
            t, m = (motion_stats([x for x, s in zip(xs, names) if s == g])["spread"] for xs in (residuals, drawn))
            print(f"  {g} ({names.count(g)} clips): spread truth {t:.2f}, model {m:.2f} (ratio {m / t:.2f})")
    ck["head_motion"] = hm.to_dict()
    ck["head_motion_fit"] = {"split": "train", "against_mean": args.against_mean, "ridge": None if args.no_speech else args.ridge,
                             "gain": "mean over clips" if args.per_clip else "geometric mean over speakers"}  # evaluate says it
    torch.save(ck, args.out or args.checkpoint)
    print(f"wrote {args.out or args.checkpoint}")
    return 0


if __name__ == "__main__":
    from talkingface.cli import run_cli  # the usual mistakes in one line

    run_cli(main)
