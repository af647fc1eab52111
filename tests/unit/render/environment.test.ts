/**
 * The studio environment prefiltered on the CPU (src/render/environment.ts): the cube's texel directions follow
 * OpenGL's face layout, level 0 is the radiance itself, and rougher levels spread the same light (their mean over
 * the sphere stays close to the radiance's mean) more evenly (smaller spread between texels).
 */
import { describe, expect, it } from 'vitest';
import { ENVIRONMENT_SIZE, cubeDirection, lodRoughness, studioLevels, studioRadiance } from '../../../src/render/environment';

/** Mean and standard deviation of the red channel over every texel of a level, each texel weighted by its solid angle. */
function stats(faces: Float32Array[], size: number): { mean: number; sd: number } {
  let w = 0, m = 0, m2 = 0;
  for (const data of faces) {
    for (let y = 0; y < size; y++) {
      for (let x = 0; x < size; x++) {
        const u = (2 * (x + 0.5)) / size - 1, v = (2 * (y + 0.5)) / size - 1;
        const omega = (1 + u * u + v * v) ** -1.5; // a texel's solid angle, up to a constant
        const r = data[4 * (y * size + x)];
        w += omega;
        m += omega * r;
        m2 += omega * r * r;
      }
    }
  }
  const mean = m / w;
  return { mean, sd: Math.sqrt(m2 / w - mean * mean) };
}

describe('studio environment', () => {
  it('maps each cube face centre to its axis, in OpenGL order (+x, -x, +y, -y, +z, -z)', () => {
    const axes = [[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]];
    axes.forEach((axis, face) => cubeDirection(face, 0, 0).forEach((c, i) => expect(c).toBeCloseTo(axis[i], 12)));
    // +x face: s runs towards -z, t towards -y (OpenGL's table of cube map faces).
    expect(cubeDirection(0, 1, 0)[2]).toBeLessThan(0);
    expect(cubeDirection(0, 0, 1)[1]).toBeLessThan(0);
  });

  it('follows three.js\'s roughness per level (0 at the mirror level, 1 at the last)', () => {
    expect(lodRoughness(0, 2)).toBe(0);
    expect(lodRoughness(2, 2)).toBe(1);
    expect(lodRoughness(1, 2)).toBeCloseTo(1 - Math.SQRT1_2, 12);
  });

  it('stores the radiance itself at level 0, mirrored in x as three.js reads cube textures', () => {
    const levels = studioLevels(16);
    const c = [0, 0, 0];
    for (const [face, x, y] of [[0, 3, 5], [2, 8, 1], [4, 12, 12], [5, 0, 15]]) {
      const d = cubeDirection(face, (2 * (x + 0.5)) / 16 - 1, (2 * (y + 0.5)) / 16 - 1);
      studioRadiance(-d[0], d[1], d[2], c);
      const at = 4 * (y * 16 + x);
      expect(levels[0][face][at]).toBeCloseTo(c[0], 5);
      expect(levels[0][face][at + 2]).toBeCloseTo(c[2], 5);
      expect(levels[0][face][at + 3]).toBe(1);
    }
  });

  it('spreads the same light more evenly at each rougher level', () => {
    const levels = studioLevels();
    expect(levels.length).toBe(Math.log2(ENVIRONMENT_SIZE / 8) + 1);
    const s = levels.map((faces, lod) => stats(faces, ENVIRONMENT_SIZE >> lod));
    for (let lod = 1; lod < s.length; lod++) {
      expect(s[lod].sd).toBeLessThan(s[lod - 1].sd);
      // n.l-weighted GGX filtering keeps the mean within a fifth (the cosine weight favours the lobe's centre).
      expect(Math.abs(s[lod].mean / s[0].mean - 1)).toBeLessThan(0.2);
    }
    // The key softbox makes level 0 far from uniform; the roughest level is a soft gradient.
    expect(s[0].sd / s[0].mean).toBeGreaterThan(1);
    expect(s[s.length - 1].sd / s[s.length - 1].mean).toBeLessThan(0.8);
  });
});
