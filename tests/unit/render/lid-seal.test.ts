/**
 * Closed lids hide the eyes (src/render/eyelids.ts, eyes.ts): with a blink fully applied and the skin kept out of
 * the balls, as Head.setFace poses it, no ray from the front, from below, from above or from aside reaches the
 * front of an eyeball without first passing through the skin. Before the lids overlapped, their edges met only at
 * their vertices, and the white showed through between them as a dotted line.
 */
import { describe, expect, it } from 'vitest';
import { ballsFor, SkinClearance } from '../../../src/render/eyes';
import { blinkField } from '../../../src/render/eyelids';
import { loadManifest, loadTemplateFile } from '../helpers/exported';
import type { FaceTemplate } from '../../../src/template/face-template';

type V3 = [number, number, number];
const sub = (a: V3, b: V3): V3 => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
const dot = (a: V3, b: V3) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const cross = (a: V3, b: V3): V3 => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];

/** Distance along `d` from `o` to the triangle (a, b, c), or Infinity (Moller-Trumbore, both faces). */
function hitTriangle(o: V3, d: V3, a: V3, b: V3, c: V3): number {
  const e1 = sub(b, a), e2 = sub(c, a), p = cross(d, e2), det = dot(e1, p);
  if (Math.abs(det) < 1e-12) return Infinity;
  const s = sub(o, a), u = dot(s, p) / det;
  if (u < 0 || u > 1) return Infinity;
  const q = cross(s, e1), v = dot(d, q) / det;
  if (v < 0 || u + v > 1) return Infinity;
  const t = dot(e2, q) / det;
  return t > 0 ? t : Infinity;
}

/**
 * Of parallel rays along `d` (unit, into the face) on a grid over each ball, those whose first hit is the front half
 * of the ball rather than the skin: [rays through, rays that reached a ball's front].
 */
function raysThrough(t: FaceTemplate, p: Float32Array, balls: ReturnType<typeof ballsFor>, d: V3, steps = 240): [number, number] {
  let through = 0, reached = 0;
  const vert = (v: number): V3 => [p[3 * v], p[3 * v + 1], p[3 * v + 2]];
  balls.centers.forEach((centre, k) => {
    const c: V3 = [centre.x, centre.y, centre.z], r = balls.radii[k];
    // Two axes across the rays.
    const u0 = cross(d, Math.abs(d[1]) < 0.9 ? [0, 1, 0] : [1, 0, 0]), un = Math.hypot(...u0);
    const u: V3 = [u0[0] / un, u0[1] / un, u0[2] / un], w = cross(d, u);
    // The skin triangles whose shadow along d falls on the ball's.
    const near: V3[][] = [];
    for (let f = 0; f < t.triangles.length; f += 3) {
      const tri = [0, 1, 2].map((i) => vert(t.triangles[f + i]));
      const across = tri.map((q) => [dot(sub(q, c), u), dot(sub(q, c), w)]);
      if (across.every((q) => q[0] < -r) || across.every((q) => q[0] > r) || across.every((q) => q[1] < -r) || across.every((q) => q[1] > r)) continue;
      near.push(tri);
    }
    for (let i = 0; i <= steps; i++) {
      for (let j = 0; j <= steps; j++) {
        const a = r * (2 * i / steps - 1), b = r * (2 * j / steps - 1);
        const o: V3 = [c[0] + a * u[0] + b * w[0] - 10 * r * d[0], c[1] + a * u[1] + b * w[1] - 10 * r * d[1], c[2] + a * u[2] + b * w[2] - 10 * r * d[2]];
        // The ray's first hit on the sphere.
        const oc = sub(o, c), h = dot(oc, d), disc = h * h - (dot(oc, oc) - r * r);
        if (disc < 0) continue;
        const tb = -h - Math.sqrt(disc);
        if (o[2] + tb * d[2] <= c[2]) continue; // the back half: behind the socket, not the lid
        reached++;
        if (near.every((tri) => hitTriangle(o, d, tri[0], tri[1], tri[2]) > tb)) through++;
      }
    }
  });
  return [through, reached];
}

const views: Record<string, V3> = {
  front: [0, 0, -1],
  below: [0, Math.sin(0.5), -Math.cos(0.5)],
  above: [0, -Math.sin(0.5), -Math.cos(0.5)],
  aside: [-Math.sin(0.7), 0, -Math.cos(0.7)],
};

describe('closed lids', () => {
  it('hide the eyeballs from the front, below, above and aside', async () => {
    const t = await loadTemplateFile(loadManifest());
    const balls = ballsFor(t);
    const clearance = new SkinClearance(t, balls.centers, balls.radii);
    const blink = blinkField(t);
    const open = t.positions.slice();
    clearance.apply(open);
    const closed = Float32Array.from(t.positions, (q, i) => q + blink[i]);
    clearance.apply(closed);
    const seen = Object.entries(views).map(([name, d]) => {
      const [atRest] = raysThrough(t, open, balls, d, 60);
      const [through, reached] = raysThrough(t, closed, balls, d);
      console.log(`${name}: open ${atRest} rays reach the ball; closed ${through} of ${reached}`);
      return { name, atRest, through };
    });
    for (const { name, atRest, through } of seen) {
      expect(atRest, `${name}: the open eye is seen`).toBeGreaterThan(0);
      expect(through, `${name}: rays through the closed lids`).toBe(0);
    }
  });
});
