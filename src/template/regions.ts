/**
 * Named vertex regions derived from a face's contour loops and its geometry.
 * The rig moves them (lips, lids, jaw, brows), the metrics read them
 * (E_vl on lips, E_ve on eyes, FDD/AFDD on the upper face) and the viewer
 * places eyeballs and the mouth backing from them.
 */
import type { RegionName } from './face-template';

export interface FaceContours {
  /** Closed loops, ordered. */
  innerLips: number[];
  outerLips: number[];
  leftEye: number[];
  rightEye: number[];
  /** Vertex sets. */
  brows: number[];
  oval: number[];
}

/** Split a closed loop at its leftmost and rightmost vertices into the upper and lower arcs (both keep the corners). */
export function splitUpperLower(loop: number[], positions: Float32Array): { upper: number[]; lower: number[] } {
  const x = (v: number) => positions[3 * v];
  const y = (v: number) => positions[3 * v + 1];
  let iMin = 0;
  let iMax = 0;
  loop.forEach((v, i) => {
    if (x(v) < x(loop[iMin])) iMin = i;
    if (x(v) > x(loop[iMax])) iMax = i;
  });
  const arc = (from: number, to: number) => {
    const out: number[] = [];
    for (let i = from; ; i = (i + 1) % loop.length) {
      out.push(loop[i]);
      if (i === to) return out;
    }
  };
  const a = arc(iMin, iMax);
  const b = arc(iMax, iMin);
  const meanY = (arr: number[]) => arr.reduce((s, v) => s + y(v), 0) / arr.length;
  return meanY(a) > meanY(b) ? { upper: a, lower: b } : { upper: b, lower: a };
}

export function regionsFromContours(c: FaceContours, positions: Float32Array): Record<RegionName | 'lips_outer_upper' | 'lips_outer_lower' | 'nose_tip', number[]> {
  const n = positions.length / 3;
  const y = (v: number) => positions[3 * v + 1];
  const inner = splitUpperLower(c.innerLips, positions);
  const outer = splitUpperLower(c.outerLips, positions);
  const left = splitUpperLower(c.leftEye, positions);
  const right = splitUpperLower(c.rightEye, positions);

  const lipTop = Math.max(...c.outerLips.map(y));
  const eyeLine = [...c.leftEye, ...c.rightEye].reduce((s, v) => s + y(v), 0) / (c.leftEye.length + c.rightEye.length);
  // Upper face for FDD/AFDD (CodeTalker's upper-face dynamics): everything above
  // halfway between the top of the lips and the eye line, so no lip motion leaks in.
  const upperLimit = (lipTop + eyeLine) / 2;
  // Jaw: everything below the mouth corners, which rotates with the mandible.
  const corners = [inner.upper[0], inner.upper[inner.upper.length - 1]];
  const cornerLine = (y(corners[0]) + y(corners[1])) / 2;

  const all = Array.from({ length: n }, (_, i) => i);
  let noseTip = 0;
  for (let v = 1; v < n; v++) if (positions[3 * v + 2] > positions[3 * noseTip + 2]) noseTip = v;
  const sorted = (a: number[]) => [...new Set(a)].sort((p, q) => p - q);
  return {
    lips_inner_upper: sorted(inner.upper),
    lips_inner_lower: sorted(inner.lower),
    lips_outer: sorted(c.outerLips),
    lips_outer_upper: sorted(outer.upper),
    lips_outer_lower: sorted(outer.lower),
    eye_left_upper: sorted(left.upper),
    eye_left_lower: sorted(left.lower),
    eye_right_upper: sorted(right.upper),
    eye_right_lower: sorted(right.lower),
    brows: sorted(c.brows),
    upper_face: all.filter((v) => y(v) > upperLimit),
    face_boundary: sorted(c.oval),
    jaw: all.filter((v) => y(v) < cornerLine),
    nose_tip: [noseTip],
  };
}
