/**
 * Posing (paper Eq. 2): the decoder's per-vertex displacement O and head pose (R, t) make the posed face
 * y = R (I + O) + t, in mm; and the conversions to the template's units that renderers want.
 */

/** y = R (I + O) + t (Eq. 2): template (N x 3) mm, offsets (F x N x 3), pose (F x 6) -> (F x N x 3). Rodrigues' formula. */
export function applyPose(template: Float32Array, offsets: Float32Array, pose: Float32Array, frames: number, out?: Float32Array): Float32Array {
  const n = template.length / 3;
  const y = out ?? new Float32Array(frames * n * 3);
  for (let f = 0; f < frames; f++) {
    const [rx, ry, rz, tx, ty, tz] = pose.subarray(f * 6, f * 6 + 6);
    const th = Math.hypot(rx, ry, rz);
    const a = th < 1e-6 ? 1 - (th * th) / 6 : Math.sin(th) / th;
    const b = th < 1e-6 ? 0.5 - (th * th) / 24 : (1 - Math.cos(th)) / (th * th);
    // R = I + a K + b K^2, K the cross-product matrix of (rx, ry, rz).
    const R = [
      1 - b * (ry * ry + rz * rz), -a * rz + b * rx * ry, a * ry + b * rx * rz,
      a * rz + b * rx * ry, 1 - b * (rx * rx + rz * rz), -a * rx + b * ry * rz,
      -a * ry + b * rx * rz, a * rx + b * ry * rz, 1 - b * (rx * rx + ry * ry),
    ];
    for (let j = 0; j < n; j++) {
      const o = (f * n + j) * 3;
      const px = template[3 * j] + offsets[o], py = template[3 * j + 1] + offsets[o + 1], pz = template[3 * j + 2] + offsets[o + 2];
      y[o] = R[0] * px + R[1] * py + R[2] * pz + tx;
      y[o + 1] = R[3] * px + R[4] * py + R[5] * pz + ty;
      y[o + 2] = R[6] * px + R[7] * py + R[8] * pz + tz;
    }
  }
  return y;
}

/**
 * The posed and the unposed face of `frames` frames in the template's units: y / mmPerUnit and
 * (I + O) / mmPerUnit, from the template in mm, the decoder's offsets (mm) and poses.
 */
export function poseFrames(templateMm: Float32Array, offsets: Float32Array, pose: Float32Array, frames: number, mmPerUnit: number): { vertices: Float32Array; unposed: Float32Array } {
  const n3 = templateMm.length;
  const vertices = applyPose(templateMm, offsets, pose, frames);
  const unposed = new Float32Array(offsets.length);
  for (let i = 0; i < vertices.length; i++) {
    vertices[i] /= mmPerUnit;
    unposed[i] = (templateMm[i % n3] + offsets[i]) / mmPerUnit;
  }
  return { vertices, unposed };
}
