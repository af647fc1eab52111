/**
 * Colouring the demo's face by a quantity at the shown frame: the error against a sample's ground truth, or the
 * decoder's attention (the pose token's over the vertices, paper Fig. 7; one vertex's over its 1-ring, Fig. 10).
 */
import type { FaceView } from '../render/face-view';
import type { TalkingFaceEngine } from '../engine/engine';
import { vertexErrors, type Truth } from './samples';

export type PaintMode = 'none' | 'error' | 'pose-attention' | 'vertex-attention';

export interface PaintRequest {
  mode: PaintMode;
  engine: TalkingFaceEngine;
  /** The audio at the model's rate (attention maps are recomputed from it). */
  samples: Float32Array;
  frame: number;
  /** Frame `frame` as drawn. */
  predicted: Float32Array;
  truth?: Truth;
  lipMask: Uint8Array | null;
  /** E_vl of the whole take (mm), computed on first use. */
  clipError: () => number;
  playing: boolean;
  /** The vertex whose attention to show (vertex-attention); default the middle of the upper outer lip. */
  vertex: number | null;
}

export class Painter {
  private job = 0;

  /**
   * `legend(html)` shows a legend line; `legend(null)` hides it. `painted(mode)` is told when a map is drawn;
   * `notice(text)` of why none is (screen readers hear it: the legend is not a live region).
   */
  constructor(private readonly view: FaceView, private readonly legend: (html: string | null) => void, private readonly painted: (mode: string) => void,
    private readonly notice: (text: string) => void) {}

  private explain(text: string): void {
    this.legend(text);
    this.notice(text);
  }

  paint(r: PaintRequest | null): void {
    const job = ++this.job;
    const n = this.view.template.vertexCount;
    if (!r || r.mode === 'none') {
      this.view.setColorMap(null);
      this.legend(null);
      return;
    }
    if (r.mode === 'error') {
      if (!r.truth) {
        this.view.setColorMap(null);
        this.explain('The error map needs a sample clip (it has ground truth).');
        return;
      }
      const f = Math.min(r.frame, r.truth.frames - 1);
      const err = vertexErrors(r.predicted, r.truth, f, 1 / r.engine.unitsPerMm);
      let lipMax = 0;
      for (let v = 0; v < n; v++) if (r.lipMask?.[v]) lipMax = Math.max(lipMax, err[v]);
      this.view.setColorMap(err, 5);
      this.legend(`Error vs ground truth: 0<span class="ramp"></span>5 mm. This frame's largest lip error ${lipMax.toFixed(2)} mm; clip E_vl ${r.clipError().toFixed(2)} mm.`);
      return;
    }
    if (r.playing) {
      this.explain('Attention maps are computed for the paused frame: pause or scrub.');
      return;
    }
    void r.engine.attentionAt(r.samples, r.frame).then((maps) => {
      if (job !== this.job) return;
      const values = new Float32Array(n);
      let max = 0;
      if (r.mode === 'pose-attention') {
        for (let v = 0; v < n; v++) max = Math.max(max, (values[v] = maps.poseToken[v]));
        this.view.setColorMap(values, max);
        this.legend(`Pose token attention, layer ${maps.layer + 1} (paper Fig. 7): 0<span class="ramp"></span>${max.toFixed(4)}; the pose token itself: ${maps.poseToken[n].toFixed(4)}.`);
      } else {
        const lips = this.view.template.regions.lips_outer_upper;
        const j = r.vertex ?? lips[Math.floor(lips.length / 2)];
        for (let k = maps.keyStart[j]; k < maps.keyStart[j + 1]; k++) max = Math.max(max, (values[maps.keys[k]] = maps.vertexWeights[k]));
        this.view.setColorMap(values, max);
        this.legend(`Vertex ${j}'s attention over itself and its ${maps.keyStart[j + 1] - maps.keyStart[j] - 1} neighbours, layer ${maps.layer + 1} (paper Fig. 10): ` +
          `0<span class="ramp"></span>${max.toFixed(3)}. Click the face, or press [ or ], to choose another vertex.`);
      }
      this.painted(r.mode);
    }, (err: Error) => job === this.job && this.explain(`Attention map failed: ${err.message}`)); // (a later one's legend stays)
  }
}
