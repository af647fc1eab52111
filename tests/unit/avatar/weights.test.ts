/** The avatar stage's head angles and named frames (src/avatar/weights.ts). */
import { describe, expect, it } from 'vitest';
import * as THREE from 'three';
import { frameWeights, yawPitchRoll } from '../../../src/avatar/weights';
import { emptyBlendshapes } from '../../../src/engine/frames';

describe('yawPitchRoll', () => {
  it("is three.js's 'YXZ' Euler angles of the axis-angle rotation", () => {
    for (const [yaw, pitch, roll] of [[0.3, -0.2, 0.1], [-0.05, 0.02, -0.4], [0, 0, 0], [1.2, 0.7, -0.9]]) {
      const q = new THREE.Quaternion().setFromEuler(new THREE.Euler(pitch, yaw, roll, 'YXZ'));
      const angle = 2 * Math.acos(Math.min(1, q.w));
      const s = Math.sqrt(1 - q.w * q.w) || 1;
      const pose = [q.x / s * angle, q.y / s * angle, q.z / s * angle];
      const out = new Float32Array(3);
      yawPitchRoll(pose, 0, out, 0);
      expect(out[0]).toBeCloseTo(yaw, 5);
      expect(out[1]).toBeCloseTo(pitch, 5);
      expect(out[2]).toBeCloseTo(roll, 5);
    }
  });
});

describe('frameWeights', () => {
  it("names one frame's values", () => {
    const b = emptyBlendshapes(2);
    b.arkit[52 + 17] = 0.5; // frame 1, jawOpen
    b.visemes[15 + 1] = 0.7; // frame 1, viseme_PP
    b.headRotation.set([0.1, 0.2, 0.3], 3);
    const w = frameWeights(b, 1);
    expect(w.arkit.jawOpen).toBe(0.5);
    expect(w.arkit.eyeBlinkLeft).toBe(0);
    expect(w.visemes.viseme_PP).toBeCloseTo(0.7, 6);
    expect(w.headRotation.yaw).toBeCloseTo(0.1, 6);
    expect(w.headRotation.roll).toBeCloseTo(0.3, 6);
  });
});
