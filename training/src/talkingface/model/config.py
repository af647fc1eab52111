"""One dataclass with every architectural choice; checkpoints and the export carry it."""
from __future__ import annotations

from dataclasses import asdict, dataclass, fields

from ..phones import CONTENT_CLASSES


# Values that fields added later had implicitly before they existed (what an older checkpoint means).
LEGACY = {"content_arch": "conv4", "template_input": False}


@dataclass(frozen=True)
class ModelConfig:
    features: str = "LG"          # hierarchical feature: "G" global only, "L" local only, "LG" both summed (Sec. III-C)
    decoder: str = "GAVA"         # "GAVA" neighbour-masked attention, "SA" unmasked self-attention, "MLP"
    variant: str = "paper"        # "paper": masked attention only; "released": graph-conv Q/K/V + one full-attention layer per block
    d_model: int = 32             # token size d (32, not 64: the browser's CPU decoder must run 10x real time on 2 cores, README)
    heads: int = 4                # attention heads (d_k = d_model / heads)
    layers: int = 3               # attention layers (the paper's Fig. 7 reads the third)
    ffn: int = 64                 # feed-forward hidden size
    content_classes: int = len(CONTENT_CLASSES)  # D: ARPAbet phones + silence + CTC-style blank (as DeepSpeech's alphabet + blank)
    content_arch: str = "dilated" # "dilated": residual dilated convolutions reading 550 ms back, 70 ms ahead (issue 14);
                                  # "conv4": the first encoder, four convolutions reading 70 ms each way
    content_channels: int = 128   # content encoder width
    content_ahead: int = 0        # "dilated" only: 0, or a last residual block reading one tap this many content frames
                                  # (20 ms each) ahead: the front-end's look-ahead, and the streaming latency, grow by as much
    template_input: bool = False  # vertex tokens also read how the subject's neutral face differs from the reference face
                                  # (encoders.HierarchicalFeature): how far lips must travel to close depends on the face;
                                  # only with the local feature (features L or LG)
    window: int = 16              # W: content frames per animation frame (paper: 16)
    window_future: int = 1        # of which after the frame: 1 x 20 ms + the encoder reach (70 ms) + half a Mel frame = 106 ms look-ahead
                                  # (3 gave 146 ms, leaving no room in the 150 ms streaming budget, README)
    content_stride: int = 2       # content frames at feature_rate / stride (100 / 2 = 50 per second, like DeepSpeech)
    pose_channels: int = 128      # pose encoder conv + LSTM width
    global_hidden: int = 128      # hidden size of f_g's MLP
    max_rotation: float = 0.5     # radians: tanh bound on predicted head rotation
    max_translation_mm: float = 50.0  # bound on predicted head translation

    def to_dict(self) -> dict:
        return asdict(self)

    @classmethod
    def from_dict(cls, d: dict) -> "ModelConfig":
        names = {f.name for f in fields(cls)}
        d = LEGACY | d  # a checkpoint written before a field existed was made with the field's old behaviour
        unknown = set(d) - names
        if unknown:
            raise ValueError(f"unknown model config keys {sorted(unknown)}: checkpoint from a newer version?")
        return cls(**d)

    @property
    def name(self) -> str:
        """The ablation row name of the paper's Table IV, e.g. "LG+GAVA"."""
        return f"{self.features}+{self.decoder}"
