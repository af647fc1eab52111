"""Numbers shared by the corpus, the model, the exporter and (through models/manifest.json) the browser."""

SAMPLE_RATE = 16000  # Hz: every waveform in the toolkit, and what the browser resamples to
FPS = 30             # animation frames per second (VOCASET is subsampled 60 -> 30, Multiface is 30)
