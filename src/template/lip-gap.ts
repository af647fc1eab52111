/**
 * The inner-lip gap as training measures it (training/src/talkingface/geometry/contours.py, contour_gap): the
 * largest vertical opening between the upper inner-lip contour's vertices (the mouth corners excluded) and the
 * lower contour, interpolated in x below each of them. Template units; 0 = touching, below 0 = pressed together.
 */
export function innerLipGaps(unposed: Float32Array, frames: number, n: number, upper: Uint32Array, lower: Uint32Array): Float32Array {
  const inner = [...upper].filter((v) => !lower.includes(v));
  const out = new Float32Array(frames);
  const order = [...lower];
  for (let f = 0; f < frames; f++) {
    const base = f * n * 3;
    const x = (v: number) => unposed[base + v * 3];
    const y = (v: number) => unposed[base + v * 3 + 1];
    order.sort((a, b) => x(a) - x(b)); // each frame's own x order, as training
    let best = -Infinity;
    for (const v of inner) {
      const xv = x(v);
      let k = 0;
      while (k < order.length - 2 && x(order[k + 1]) < xv) k++;
      const a = order[k], b = order[k + 1];
      const t = Math.min(1, Math.max(0, (xv - x(a)) / (x(b) - x(a) || 1)));
      best = Math.max(best, y(v) - (y(a) + t * (y(b) - y(a))));
    }
    out[f] = best;
  }
  return out;
}
