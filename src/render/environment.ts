/**
 * The studio the wet surfaces (eyes, teeth, tongue) reflect: a radiance defined in code and prefiltered on the CPU
 * into the mip chain three.js's physically based materials sample (a "PMREM": level 0 a mirror, the last level
 * roughness 1; three.js's PMREMGenerator.lodToRoughness maps one to the other).
 *
 * Why not three.js's PMREMGenerator: it renders and filters on the GPU with shaders whose compilation took 2.5 s of
 * the page's main thread under SwiftShader (a software GPU, as in headless browsers and on machines without one),
 * during which onnxruntime could not create its sessions: the model was ready 3 s later. Here the same kind of map
 * costs a few milliseconds of JavaScript and no shader at all, on every machine.
 *
 * The studio: a soft vertical gradient (bright ceiling, darker floor), a large warm softbox where the key light is,
 * a cool fill, a rim behind and a ceiling panel; each a smooth lobe, so that a small cube map holds it. Prefiltering
 * follows the split-sum approximation (n = v = r): GGX importance samples around each texel's direction, weighted
 * by n.l, on a fixed Hammersley set (the same map on every load).
 */
import * as THREE from 'three';

/** The mirror level's cube face size; the chain goes down to 8 texels (three.js's LOD_MIN = 3). */
export const ENVIRONMENT_SIZE = 32;
const SMALLEST = 8;
const SAMPLES = 64;

interface Lobe {
  dir: [number, number, number];
  /** Sharpness k of the lobe exp(k (cos(angle) - 1)), about exp(-(angle / w)^2) for k = 2 / w^2; radiance (linear RGB) at its centre. */
  k: number;
  rgb: [number, number, number];
}

const sharpness = (width: number) => 2 / (width * width);

const normalize = (x: number, y: number, z: number): [number, number, number] => {
  const n = Math.hypot(x, y, z);
  return [x / n, y / n, z / n];
};

/** World directions as the head's scene uses them: +y up, +z towards the viewer, +x to the viewer's right. */
const LOBES: Lobe[] = [
  { dir: normalize(0.7, 0.9, 1.4), k: sharpness(0.32), rgb: [3.2, 3.0, 2.7] }, // key softbox, where the key light is
  { dir: normalize(0.7, 0.9, 1.4), k: sharpness(0.22), rgb: [14, 13.4, 12.4] }, // its bright centre: the eyes' catchlight
  { dir: normalize(-1.2, 0.1, 0.9), k: sharpness(0.45), rgb: [1.1, 1.3, 1.6] }, // cool fill
  { dir: normalize(-0.6, 0.7, -1.2), k: sharpness(0.3), rgb: [1.6, 1.7, 2.0] }, // rim behind
  { dir: [0, 1, 0], k: sharpness(0.5), rgb: [1.8, 1.75, 1.7] }, // ceiling panel
];

/** LOBES flat, seven numbers a lobe: k dir (3), k, rgb (3); studioRadiance reads them for every sample of the prefilter. */
const LOBE_TERMS = Float64Array.from(LOBES.flatMap((l) => [l.k * l.dir[0], l.k * l.dir[1], l.k * l.dir[2], l.k, ...l.rgb]));

/** The studio's radiance (linear RGB) in the world direction d (unit length), written to out. */
export function studioRadiance(dx: number, dy: number, dz: number, out: Float32Array | Float64Array | number[], at = 0): void {
  // The room: the floor darker and warmer, the ceiling a light grey.
  const up = 0.5 + 0.5 * dy;
  let r = 0.1 + 0.32 * up, g = 0.09 + 0.31 * up, b = 0.08 + 0.3 * up;
  const L = LOBE_TERMS;
  for (let i = 0; i < L.length; i += 7) {
    const e = dx * L[i] + dy * L[i + 1] + dz * L[i + 2] - L[i + 3]; // k (d.dir - 1)
    // Far from a lobe it adds less than e^-20 x 14 (3e-8) to a radiance of 0.08 or more, below what the texture's
    // half floats hold (1 part in 2048); the exponential is most of the prefilter's time.
    if (e < -20) continue;
    const w = Math.exp(e);
    r += w * L[i + 4];
    g += w * L[i + 5];
    b += w * L[i + 6];
  }
  out[at] = r;
  out[at + 1] = g;
  out[at + 2] = b;
}

/** The cube map face `face` (OpenGL order +x, -x, +y, -y, +z, -z) direction through texel (u, v) in [-1, 1]. */
export function cubeDirection(face: number, u: number, v: number): [number, number, number] {
  switch (face) {
    case 0: return normalize(1, -v, -u);
    case 1: return normalize(-1, -v, u);
    case 2: return normalize(u, 1, v);
    case 3: return normalize(u, -1, -v);
    case 4: return normalize(u, -v, 1);
    default: return normalize(-u, -v, -1);
  }
}

/** three.js's PMREMGenerator.lodToRoughness: level `lod` of `maxLod` holds this roughness. */
export const lodRoughness = (lod: number, maxLod: number) => (maxLod > 0 ? 1 - Math.sqrt(1 - lod / maxLod) : 0);

/** Hammersley point i of n: (i / n, radical inverse of i in base 2). */
function hammersley(i: number, n: number): [number, number] {
  let bits = i;
  bits = ((bits << 16) | (bits >>> 16)) >>> 0;
  bits = (((bits & 0x55555555) << 1) | ((bits & 0xaaaaaaaa) >>> 1)) >>> 0;
  bits = (((bits & 0x33333333) << 2) | ((bits & 0xcccccccc) >>> 2)) >>> 0;
  bits = (((bits & 0x0f0f0f0f) << 4) | ((bits & 0xf0f0f0f0) >>> 4)) >>> 0;
  bits = (((bits & 0x00ff00ff) << 8) | ((bits & 0xff00ff00) >>> 8)) >>> 0;
  return [i / n, bits / 2 ** 32];
}

/**
 * GGX importance samples of the half vector h for one roughness (alpha = roughness^2), in a tangent frame whose z is
 * n, and each one's weight n.l = 2 (n.h)^2 - 1 (l = 2 (n.h) h - n, v = n). Only those with n.l > 0, which are the
 * same for every direction n: computed once per roughness, not once per texel.
 */
interface GgxSamples {
  /** h per sample: x, y, z (z = n.h) in the tangent frame. */
  h: Float64Array;
  /** n.l per sample, and their sum. */
  weight: Float64Array;
  total: number;
}

const ggxSets = new Map<number, GgxSamples>();

function ggxSamples(roughness: number): GgxSamples {
  let set = ggxSets.get(roughness);
  if (set) return set;
  const a = roughness * roughness;
  const h: number[] = [], weight: number[] = [];
  for (let i = 0; i < SAMPLES; i++) {
    const [xi1, xi2] = hammersley(i, SAMPLES);
    const phi = 2 * Math.PI * xi1;
    const cosT = Math.sqrt((1 - xi2) / (1 + (a * a - 1) * xi2));
    const sinT = Math.sqrt(1 - cosT * cosT);
    const nl = 2 * cosT * cosT - 1;
    if (nl <= 0) continue;
    h.push(sinT * Math.cos(phi), sinT * Math.sin(phi), cosT);
    weight.push(nl);
  }
  set = { h: Float64Array.from(h), weight: Float64Array.from(weight), total: weight.reduce((sum, w) => sum + w, 0) };
  ggxSets.set(roughness, set);
  return set;
}

/**
 * The studio's radiance prefiltered for roughness `roughness` in direction n: the n.l-weighted mean of GGX
 * importance samples (alpha = roughness^2) around n, with v = n.
 */
export function prefiltered(n: [number, number, number], roughness: number, out: Float32Array, at: number): void {
  if (roughness <= 0) return studioRadiance(n[0], n[1], n[2], out, at);
  const { h, weight, total } = ggxSamples(roughness);
  // A tangent frame around n.
  const [nx, ny, nz] = n;
  const [tx, ty, tz] = Math.abs(nz) < 0.999 ? normalize(-ny, nx, 0) : normalize(0, -nz, ny);
  const bx = ny * tz - nz * ty, by = nz * tx - nx * tz, bz = nx * ty - ny * tx;
  const c = radiance;
  let r = 0, g = 0, b = 0;
  for (let i = 0; i < weight.length; i++) {
    const hx = h[3 * i], hy = h[3 * i + 1], hz = h[3 * i + 2];
    // h in the world, then l = 2 (n.h) h - n.
    const wx = hx * tx + hy * bx + hz * nx, wy = hx * ty + hy * by + hz * ny, wz = hx * tz + hy * bz + hz * nz;
    studioRadiance(2 * hz * wx - nx, 2 * hz * wy - ny, 2 * hz * wz - nz, c);
    r += weight[i] * c[0];
    g += weight[i] * c[1];
    b += weight[i] * c[2];
  }
  out[at] = r / total;
  out[at + 1] = g / total;
  out[at + 2] = b / total;
}

/** prefiltered's scratch: one sample's radiance. */
const radiance = new Float64Array(3);

/**
 * The prefiltered studio as linear RGBA floats: levels[lod][face] holds size >> lod squared texels, rows top to
 * bottom as OpenGL uploads them. `flipX` mirrors x, as three.js does when it samples a cube texture that is not a
 * render target (its cube maps follow the skybox convention).
 */
export function studioLevels(size = ENVIRONMENT_SIZE, flipX = true): Float32Array[][] {
  const maxLod = Math.log2(size / SMALLEST);
  const levels: Float32Array[][] = [];
  for (let lod = 0; lod <= maxLod; lod++) {
    const s = size >> lod;
    const roughness = lodRoughness(lod, maxLod);
    const faces: Float32Array[] = [];
    for (let face = 0; face < 6; face++) {
      const data = new Float32Array(s * s * 4);
      for (let y = 0; y < s; y++) {
        for (let x = 0; x < s; x++) {
          const d = cubeDirection(face, (2 * (x + 0.5)) / s - 1, (2 * (y + 0.5)) / s - 1);
          if (flipX) d[0] = -d[0];
          const at = 4 * (y * s + x);
          prefiltered(d, roughness, data, at);
          data[at + 3] = 1;
        }
      }
      faces.push(data);
    }
    levels.push(faces);
  }
  return levels;
}

/**
 * The studio as a texture three.js's standard and physical materials use as their environment map directly
 * (marked as already prefiltered, so the renderer does not run its PMREM generator on it).
 */
export function studioEnvironment(size = ENVIRONMENT_SIZE): THREE.Texture {
  const levels = studioLevels(size);
  const faces = [0, 1, 2, 3, 4, 5].map((face) => {
    const mipmaps = levels.map((level, lod) => ({
      data: toHalf(level[face]),
      width: size >> lod,
      height: size >> lod,
    }));
    return new THREE.CompressedTexture(mipmaps, size, size, UNCOMPRESSED_RGBA, THREE.HalfFloatType);
  });
  const texture = new THREE.CompressedCubeTexture(faces, UNCOMPRESSED_RGBA, THREE.HalfFloatType);
  texture.name = 'studio';
  texture.colorSpace = THREE.LinearSRGBColorSpace;
  texture.minFilter = THREE.LinearMipmapLinearFilter;
  texture.magFilter = THREE.LinearFilter;
  texture.generateMipmaps = false;
  // Read by three.js's WebGLPrograms (ENVMAP_TYPE_PMREM, its size and level count from image[0].mipmaps) and
  // WebGLEnvironments (a PMREM texture is used as it is).
  (texture as unknown as { isPMREMTexture: boolean }).isPMREMTexture = true;
  texture.needsUpdate = true;
  return texture;
}

/** Plain RGBA: three.js uploads a "compressed" cube texture of this format with texSubImage2D, level by level. */
const UNCOMPRESSED_RGBA = THREE.RGBAFormat as unknown as THREE.CompressedPixelFormat;

function toHalf(values: Float32Array): Uint16Array {
  const out = new Uint16Array(values.length);
  for (let i = 0; i < values.length; i++) out[i] = THREE.DataUtils.toHalfFloat(values[i]);
  return out;
}
