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


def _wav(fmt: bytes, data: bytes) -> bytes:
    chunks = b"fmt " + len(fmt).to_bytes(4, "little") + fmt + b"data" + len(data).to_bytes(4, "little") + data
    return b"RIFF" + (4 + len(chunks)).to_bytes(4, "little") + b"WAVE" + chunks


def _extensible(sub: int, bits: int, channels: int = 1, rate: int = 16000) -> bytes:
    """WAVE_FORMAT_EXTENSIBLE's fmt chunk (as ffmpeg writes beyond 16 bits): the format is its sub-format GUID's first two bytes."""
    block = channels * bits // 8
    return (0xFFFE.to_bytes(2, "little") + channels.to_bytes(2, "little") + rate.to_bytes(4, "little") + (rate * block).to_bytes(4, "little")
            + block.to_bytes(2, "little") + bits.to_bytes(2, "little") + (22).to_bytes(2, "little") + bits.to_bytes(2, "little")
            + (4).to_bytes(4, "little") + sub.to_bytes(2, "little") + bytes.fromhex("000000001000800000aa00389b71"))


def test_extensible_wav_is_read_by_its_sub_format(tmp_path):
    floats = np.array([0.25, -0.5, 0.75], "<f4")
    (tmp_path / "f.wav").write_bytes(_wav(_extensible(3, 32), floats.tobytes()))
    y, sr = read_wav(tmp_path / "f.wav")
    assert sr == 16000 and np.allclose(y, floats)
    (tmp_path / "p.wav").write_bytes(_wav(_extensible(1, 16), np.array([16384], "<i2").tobytes()))
    assert np.allclose(read_wav(tmp_path / "p.wav")[0], [0.5])
    (tmp_path / "law.wav").write_bytes(_wav(_extensible(7, 16), bytes(4)))  # mu-law, said to be 16-bit: not PCM
    with pytest.raises(WavError, match="encoding 7 with 16 bits is not supported"):
        read_wav(tmp_path / "law.wav")


def test_a_damaged_fmt_chunk_is_said_not_divided_by(tmp_path):
    (tmp_path / "z.wav").write_bytes(_wav(_extensible(1, 16, channels=0), bytes(4)))
    with pytest.raises(WavError, match=r"fmt chunk is damaged \(0 channels"):
        wav_seconds(tmp_path / "z.wav")
    (tmp_path / "adpcm.wav").write_bytes(_wav(_extensible(0x11, 4), bytes(4)))  # IMA ADPCM: 4 bits, a codec, not damage
    with pytest.raises(WavError, match="encoding 17 with 4 bits is not supported"):
        wav_seconds(tmp_path / "adpcm.wav")
