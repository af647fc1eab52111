"""Audio augmentation, so the model hears speech the way a browser microphone delivers it.

Speed (sox tempo, phone times rescaled), pitch (sox pitch, times unchanged),
loudness and clipping, background noise (white, pink, brown, hum, speech-shaped)
at a random SNR, reverberation (a synthetic exponentially decaying room
response), band-limiting (telephone 300-3400 Hz at 8 kHz, or a random low-pass)
and microphone colouring (a smooth random EQ curve). Each is drawn per clip
from the clip's own seeded generator, and the draw is recorded with the clip.
`vocode` (the speech front-end's set only, frontend/speechset.py --vocode) says speech again through
a simple vocoder, as diphone and parametric synthesisers do.
"""
from __future__ import annotations

import subprocess

import numpy as np

from ..wav import resample


def _sox(audio: np.ndarray, sr: int, *effect: str) -> np.ndarray:
    res = subprocess.run(
        ["sox", "-R", "-t", "f32", "-r", str(sr), "-c", "1", "-", "-t", "f32", "-r", str(sr), "-c", "1", "-", *effect],
        input=audio.astype("<f4").tobytes(), capture_output=True, check=True)
    return np.frombuffer(res.stdout, "<f4").astype(np.float32)


def change_tempo(audio: np.ndarray, sr: int, factor: float, phones):
    """Speak `factor` times faster without changing pitch (WSOLA); phone times follow."""
    out = _sox(audio, sr, "tempo", "-s", f"{factor:.4f}")
    scale = len(out) / len(audio)
    return out, [(p, a * scale, b * scale) for p, a, b in phones]


def shift_pitch(audio: np.ndarray, sr: int, cents: float) -> np.ndarray:
    out = _sox(audio, sr, "pitch", f"{cents:.1f}")
    return _match_length(out, len(audio))


def _match_length(x: np.ndarray, n: int) -> np.ndarray:
    return x[:n] if len(x) >= n else np.pad(x, (0, n - len(x)))


def _spectral_curve(n: int, sr: int, gains_db) -> np.ndarray:
    """rfft-bin gains from a function of frequency in Hz returning dB."""
    f = np.fft.rfftfreq(n, 1.0 / sr)
    return 10 ** (gains_db(np.maximum(f, 1.0)) / 20)


def coloured_noise(n: int, sr: int, kind: str, rng: np.random.Generator, speech: np.ndarray | None = None) -> np.ndarray:
    if kind == "hum":
        t = np.arange(n) / sr
        f0 = rng.choice([50.0, 60.0])
        x = sum(np.sin(2 * np.pi * f0 * k * t + rng.uniform(0, 2 * np.pi)) / k for k in range(1, 6))
        return (x + 0.05 * rng.standard_normal(n)).astype(np.float32)
    spec = np.fft.rfft(rng.standard_normal(n))
    f = np.maximum(np.fft.rfftfreq(n, 1.0 / sr), 20.0)
    if kind == "pink":
        spec /= np.sqrt(f)
    elif kind == "brown":
        spec /= f
    elif kind == "speech" and speech is not None:
        # Long-term speech spectrum of the clip itself, smoothed: a babble-like background.
        env = np.abs(np.fft.rfft(speech, n))
        k = max(1, len(env) // 200)
        env = np.convolve(env, np.ones(k) / k, mode="same")
        spec *= env
    return np.fft.irfft(spec, n).astype(np.float32)


def add_noise(audio: np.ndarray, noise: np.ndarray, snr_db: float) -> np.ndarray:
    p_sig = np.mean(audio ** 2) + 1e-12
    p_noise = np.mean(noise ** 2) + 1e-12
    return (audio + noise * np.sqrt(p_sig / (p_noise * 10 ** (snr_db / 10)))).astype(np.float32)


def reverberate(audio: np.ndarray, sr: int, rt60: float, wet: float, rng: np.random.Generator) -> np.ndarray:
    """Convolve with decaying noise (60 dB down at rt60 s), a direct path first; the tail is cut at the clip end."""
    n_ir = int(rt60 * sr)
    t = np.arange(n_ir) / sr
    ir = rng.standard_normal(n_ir) * np.exp(-6.91 * t / rt60)
    ir[: int(0.002 * sr)] = 0.0
    ir = ir / (np.sqrt(np.sum(ir ** 2)) + 1e-12)
    n = len(audio) + n_ir
    tail = np.fft.irfft(np.fft.rfft(audio, n) * np.fft.rfft(ir, n), n)[: len(audio)]
    out = (1 - wet) * audio + wet * tail * (np.std(audio) / (np.std(tail) + 1e-12))
    return out.astype(np.float32)


def telephone(audio: np.ndarray, sr: int) -> np.ndarray:
    """8 kHz telephone channel: 300-3400 Hz, then back to the corpus rate."""
    narrow = resample(audio, sr, 8000)
    spec = np.fft.rfft(narrow)
    f = np.fft.rfftfreq(len(narrow), 1 / 8000)
    spec *= 1 / np.sqrt(1 + (300 / np.maximum(f, 1)) ** 8) / np.sqrt(1 + (f / 3400) ** 8)
    return _match_length(resample(np.fft.irfft(spec, len(narrow)).astype(np.float32), 8000, sr), len(audio))


def lowpass(audio: np.ndarray, sr: int, cutoff: float) -> np.ndarray:
    g = _spectral_curve(len(audio), sr, lambda f: -10 * np.log10(1 + (f / cutoff) ** 8))
    return np.fft.irfft(np.fft.rfft(audio) * g, len(audio)).astype(np.float32)


def microphone_colour(audio: np.ndarray, sr: int, rng: np.random.Generator) -> np.ndarray:
    """A smooth random EQ: three bumps of +-6 dB on a log-frequency axis, plus a tilt."""
    centres = np.exp(rng.uniform(np.log(120), np.log(6000), 3))
    gains = rng.uniform(-6, 6, 3)
    widths = rng.uniform(0.3, 1.0, 3)
    tilt = rng.uniform(-3, 3)

    def db(f):
        lf = np.log2(f / 1000.0)
        return tilt * lf / 3 + sum(g * np.exp(-0.5 * ((np.log2(f / c)) / w) ** 2) for c, g, w in zip(centres, gains, widths))
    g = _spectral_curve(len(audio), sr, db)
    return np.fft.irfft(np.fft.rfft(audio) * g, len(audio)).astype(np.float32)


def augment_speech(audio: np.ndarray, sr: int, phones, rng: np.random.Generator, strength: float = 1.0):
    """What changes the speaker: speaking rate and voice pitch. Returns (audio, phones, description)."""
    desc: dict = {}
    x = audio.astype(np.float32)
    if rng.random() < 0.5 * strength:
        f = float(rng.uniform(0.88, 1.15))
        x, phones = change_tempo(x, sr, f, phones)
        desc["tempo"] = round(f, 3)
    if rng.random() < 0.5 * strength:
        c = float(rng.uniform(-300, 300))
        x = shift_pitch(x, sr, c)
        desc["pitch_cents"] = round(c, 1)
    return x, phones, desc


def augment_channel(audio: np.ndarray, sr: int, rng: np.random.Generator, strength: float = 1.0):
    """What the recording chain does: microphone, room, noise, bandwidth, level. Returns (audio, description)."""
    desc: dict = {}
    x = audio.astype(np.float32)
    if rng.random() < 0.4 * strength:
        x = microphone_colour(x, sr, rng)
        desc["mic_colour"] = True
    if rng.random() < 0.3 * strength:
        rt = float(rng.uniform(0.2, 0.8))
        wet = float(rng.uniform(0.15, 0.5))
        x = reverberate(x, sr, rt, wet, rng)
        desc["reverb"] = {"rt60": round(rt, 2), "wet": round(wet, 2)}
    if rng.random() < 0.5 * strength:
        kind = str(rng.choice(["white", "pink", "brown", "hum", "speech"]))
        snr = float(rng.uniform(5, 35))
        x = add_noise(x, coloured_noise(len(x), sr, kind, rng, x), snr)
        desc["noise"] = {"kind": kind, "snr_db": round(snr, 1)}
    r = rng.random()
    if r < 0.12 * strength:
        x = telephone(x, sr)
        desc["band"] = "telephone"
    elif r < 0.25 * strength:
        c = float(rng.uniform(3000, 7000))
        x = lowpass(x, sr, c)
        desc["band"] = f"lowpass {c:.0f} Hz"
    # Level: peak-normalise, then a random gain; now and then drive it into clipping.
    x = x / (np.max(np.abs(x)) + 1e-9)
    if rng.random() < 0.08 * strength:
        drive = float(rng.uniform(1.3, 3.0))
        x = np.clip(x * drive, -1, 1)
        desc["clipping_drive"] = round(drive, 2)
    else:
        gain_db = float(rng.uniform(-20, -1)) if strength > 0 else -3.0
        x = x * 10 ** (gain_db / 20)
        desc["gain_db"] = round(gain_db, 1)
    return x.astype(np.float32), desc


# ---- a synthesiser's vocoder -----------------------------------------------------------------------------

VOCODE_FRAME, VOCODE_HOP = 512, 128      # at 16 kHz: 32 ms frames every 8 ms
VOCODE_CEPSTRA = 30                      # cepstral coefficients kept for the envelope (the vocal tract, not the pitch)


def vocode(audio: np.ndarray, sr: int, rng: np.random.Generator, noise_mix: float | None = None) -> np.ndarray:
    """Speech as a vocoder-based synthesiser would say it: each frame's spectral envelope (cepstrally smoothed) excited
    by a pulse train at the speech's own pitch where it is voiced and by noise where it is not, then overlap-added.
    The words, their timing and the vocal tract stay; the voice's own source goes, buzzy as in diphone (LPC) and
    statistical-parametric (mel-cepstral) voices. `noise_mix`: share of noise in voiced frames (default: drawn, 0-0.3)."""
    from .prosody import frame_pitch
    x = audio.astype(np.float64)
    n, N, H = len(x), VOCODE_FRAME, VOCODE_HOP
    if n < N:
        return audio.astype(np.float32)
    frames = 1 + (n - N) // H
    win = np.hanning(N + 1)[:-1]
    idx = np.arange(N)[None, :] + H * np.arange(frames)[:, None]
    spec = np.fft.rfft(x[idx] * win, axis=1)                                      # (frames, N/2+1)
    ceps = np.fft.irfft(np.log(np.abs(spec) + 1e-8), N, axis=1)
    ceps[:, VOCODE_CEPSTRA:N - VOCODE_CEPSTRA + 1] = 0.0                          # lifter: keep the envelope
    envelope = np.exp(np.fft.rfft(ceps, axis=1).real)
    # Excitation: pulses at the frame's pitch (phase carried from sample to sample), noise where unvoiced.
    f0 = frame_pitch(audio, sr, frames, sr / H)                                    # frame i at sample i * H
    t = np.arange(n) / H
    f0s = np.interp(t, np.arange(frames), f0)
    voiced = np.interp(t, np.arange(frames), (f0 > 0).astype(np.float64)) > 0.5
    phase = np.cumsum(np.where(voiced, f0s, 0.0) / sr)
    pulses = np.zeros(n)
    pulses[1:][np.diff(np.floor(phase)) > 0] = 1.0
    mix = float(rng.uniform(0.0, 0.3)) if noise_mix is None else noise_mix
    noise = rng.standard_normal(n)
    pulses *= np.sqrt(sr / np.maximum(f0s, 50.0))                                  # unit power at any pitch
    excitation = np.where(voiced, np.sqrt(1 - mix) * pulses + np.sqrt(mix) * noise, noise)
    exc = np.fft.rfft(excitation[idx] * win, axis=1)
    exc /= np.sqrt(np.mean(np.abs(exc) ** 2, axis=1, keepdims=True)) + 1e-12    # flat on average: the envelope sets the level
    y_frames = np.fft.irfft(exc * envelope, N, axis=1) * win
    y, norm = np.zeros(n), np.zeros(n)
    np.add.at(y, idx, y_frames)
    np.add.at(norm, idx, np.broadcast_to(win ** 2, y_frames.shape))
    y /= np.maximum(norm, 1e-3)
    peak = np.max(np.abs(y)) + 1e-9
    return (y / peak * min(1.0, float(np.max(np.abs(x))) or 1.0)).astype(np.float32)
