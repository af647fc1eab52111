"""The toolkit's WAV reader and writer: a round trip, a stereo file written by another writer, a file that is not WAV."""
import wave

import numpy as np
import pytest

from talkingface.wav import WavError, read_wav, wav_seconds, write_wav


def test_wav_round_trip_and_stereo(tmp_path):
    x = (0.5 * np.sin(np.linspace(0, 50, 8000))).astype(np.float32)
    write_wav(tmp_path / "a.wav", x, 8000)
    y, sr = read_wav(tmp_path / "a.wav")
    assert sr == 8000 and np.abs(x - y).max() < 1e-4
    assert wav_seconds(tmp_path / "a.wav") == 1.0
    with wave.open(str(tmp_path / "s.wav"), "wb") as w:
        w.setnchannels(2); w.setsampwidth(2); w.setframerate(16000)
        w.writeframes(np.stack([np.full(100, 1000), np.full(100, 3000)], 1).astype("<i2").tobytes())
    y, _ = read_wav(tmp_path / "s.wav")
    assert y.shape == (100,) and np.allclose(y, 2000 / 32768)
    (tmp_path / "bad.wav").write_bytes(b"not a wav at all")
    with pytest.raises(WavError, match="not a WAV"):
        read_wav(tmp_path / "bad.wav")
