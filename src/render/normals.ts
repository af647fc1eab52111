/**
 * Vertex normals of a mesh of which only some vertices move: the triangles that touch no moving vertex are summed
 * once, and each frame only the triangles that do are summed again on top of that (area-weighted face normals, as
 * three.js's computeVertexNormals). For the head: the face, the skin under the chin and the mouth move; most of
 * the skull does not, so a frame costs about what the face's own normals cost.
 */
export class PartialNormals {
  private readonly fixedSum: Float32Array;
  private readonly moving: Uint32Array;
  /** Vertices whose normal changes: those of the moving triangles. */
  private readonly touched: Uint32Array;

  constructor(private readonly index: ArrayLike<number>, positions: Float32Array, isMoving: (v: number) => boolean) {
    this.fixedSum = new Float32Array(positions.length);
    const moving: number[] = [];
    const touched = new Set<number>();
    for (let t = 0; t < index.length; t += 3) {
      const [a, b, c] = [index[t], index[t + 1], index[t + 2]];
      if (isMoving(a) || isMoving(b) || isMoving(c)) {
        moving.push(t);
        touched.add(a).add(b).add(c);
      } else addFaceNormal(positions, a, b, c, this.fixedSum);
    }
    this.moving = Uint32Array.from(moving);
    this.touched = Uint32Array.from(touched);
  }

  /** Full normals into `out` (once, e.g. at start). */
  init(positions: Float32Array, out: Float32Array): void {
    out.set(this.fixedSum);
    for (let i = 0; i < this.index.length; i += 3) {
      if (!this.isMovingTriangle(i)) continue;
      addFaceNormal(positions, this.index[i], this.index[i + 1], this.index[i + 2], out);
    }
    normalise(out, null);
  }

  /** Recompute the normals of the vertices the moving triangles touch. */
  update(positions: Float32Array, out: Float32Array): void {
    const idx = this.index;
    for (const v of this.touched) {
      out[3 * v] = this.fixedSum[3 * v];
      out[3 * v + 1] = this.fixedSum[3 * v + 1];
      out[3 * v + 2] = this.fixedSum[3 * v + 2];
    }
    for (const t of this.moving) addFaceNormal(positions, idx[t], idx[t + 1], idx[t + 2], out);
    normalise(out, this.touched);
  }

  private isMovingTriangle(t: number): boolean {
    // `moving` is sorted: binary search.
    let lo = 0, hi = this.moving.length;
    while (lo < hi) {
      const mid = (lo + hi) >> 1;
      if (this.moving[mid] < t) lo = mid + 1;
      else hi = mid;
    }
    return this.moving[lo] === t;
  }
}

function addFaceNormal(p: Float32Array, a: number, b: number, c: number, out: Float32Array): void {
  const ax = p[3 * a], ay = p[3 * a + 1], az = p[3 * a + 2];
  const ux = p[3 * b] - ax, uy = p[3 * b + 1] - ay, uz = p[3 * b + 2] - az;
  const wx = p[3 * c] - ax, wy = p[3 * c + 1] - ay, wz = p[3 * c + 2] - az;
  // (c - b) x (a - b) in three.js; the same as (b - a) x (c - a).
  const nx = uy * wz - uz * wy, ny = uz * wx - ux * wz, nz = ux * wy - uy * wx;
  for (const v of [a, b, c]) {
    out[3 * v] += nx;
    out[3 * v + 1] += ny;
    out[3 * v + 2] += nz;
  }
}

function normalise(out: Float32Array, only: Uint32Array | null): void {
  const count = only ? only.length : out.length / 3;
  for (let i = 0; i < count; i++) {
    const v = only ? only[i] : i;
    const x = out[3 * v], y = out[3 * v + 1], z = out[3 * v + 2];
    const l = Math.hypot(x, y, z) || 1;
    out[3 * v] = x / l;
    out[3 * v + 1] = y / l;
    out[3 * v + 2] = z / l;
  }
}
