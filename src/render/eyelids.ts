/**
 * A blink as a displacement of the face's vertices: what the idle face adds, times a weight from 0 (open) to
 * 1 (closed), to close its lids over the eyes, at rest and during speech where the model's own lids are open
 * (lidOpening: a model that blinks by itself is not closed twice).
 *
 * For each eye the upper lid's contour travels 90% of the way down to the lower contour below it and the lower
 * contour 20% up, so the upper lid passes over the lower by a tenth of the opening (edges that only met showed the
 * white between their vertices, a dotted line from below); the skin within reach of a contour follows its nearest
 * contour vertex, fading with distance (like the corpus rig's lid fields). The eye corners stay.
 */
import type { FaceTemplate } from '../template/face-template';

export function blinkField(t: FaceTemplate): Float32Array {
  const p = t.positions;
  const d = new Float32Array(t.vertexCount * 3);
  for (const side of ['left', 'right'] as const) {
    const up = [...t.regions[`eye_${side}_upper`]];
    const lo = [...t.regions[`eye_${side}_lower`]];
    const corners = new Set(up.filter((v) => lo.includes(v)));
    const xs = [...up, ...lo].map((v) => p[3 * v]);
    const width = Math.max(...xs) - Math.min(...xs);
    /** The point of `arc` at x (linear between its vertices sorted by x). */
    const at = (arc: number[], x: number, k: number) => {
      const s = [...arc].sort((a, b) => p[3 * a] - p[3 * b]);
      let i = 0;
      while (i < s.length - 2 && p[3 * s[i + 1]] < x) i++;
      const a = s[i], b = s[i + 1];
      const f = Math.min(1, Math.max(0, (x - p[3 * a]) / (p[3 * b] - p[3 * a] || 1)));
      return p[3 * a + k] + f * (p[3 * b + k] - p[3 * a + k]);
    };
    const contour = new Map<number, number[]>();
    for (const [own, other, share] of [[up, lo, 0.9], [lo, up, 0.2]] as const) {
      for (const v of own) {
        if (corners.has(v)) continue;
        const x = p[3 * v];
        const dy = (at(other, x, 1) - p[3 * v + 1]) * share;
        // The closing lid rides over the cornea: a little forward at mid-travel is kept by moving to the far contour's depth.
        const dz = (Math.max(at(other, x, 2), p[3 * v + 2]) - p[3 * v + 2]) * share;
        contour.set(v, [0, dy, dz]);
      }
    }
    const reachUp = 0.45 * width, reachLo = 0.3 * width;
    for (let v = 0; v < t.vertexCount; v++) {
      if (corners.has(v)) continue;
      if (contour.has(v)) {
        d.set(contour.get(v)!, 3 * v);
        continue;
      }
      let best = -1, bestD = Infinity;
      for (const c of contour.keys()) {
        const dist = Math.hypot(p[3 * v] - p[3 * c], p[3 * v + 1] - p[3 * c + 1], p[3 * v + 2] - p[3 * c + 2]);
        if (dist < bestD) [best, bestD] = [c, dist];
      }
      const reach = up.includes(best) ? reachUp : reachLo;
      if (best < 0 || bestD >= reach) continue;
      const f = (1 - bestD / reach) ** 2;
      const dc = contour.get(best)!;
      for (let k = 0; k < 3; k++) d[3 * v + k] += dc[k] * f;
    }
  }
  return d;
}

/**
 * Each upper-lid vertex paired with the lower-lid vertex nearest it across (both eyes, the corners left out), as
 * [upper, lower, upper, lower, ...]: what lidOpening measures.
 */
export function lidPairs(t: FaceTemplate): Uint32Array {
  const pairs: number[] = [];
  const x = (v: number) => t.positions[3 * v];
  for (const side of ['left', 'right'] as const) {
    const up = t.regions[`eye_${side}_upper`], lo = t.regions[`eye_${side}_lower`];
    for (const u of up) {
      if (lo.includes(u)) continue; // a corner
      let below = lo[0];
      for (const l of lo) if (Math.abs(x(l) - x(u)) < Math.abs(x(below) - x(u))) below = l;
      pairs.push(u, below);
    }
  }
  return Uint32Array.from(pairs);
}

/** The eyes' opening in `positions` (the template's layout): the mean height of the upper lid over the lower (lidPairs). */
export function lidOpening(positions: Float32Array, pairs: Uint32Array): number {
  let sum = 0;
  for (let i = 0; i < pairs.length; i += 2) sum += positions[3 * pairs[i] + 1] - positions[3 * pairs[i + 1] + 1];
  return pairs.length ? sum / (pairs.length / 2) : 0;
}
