/**
 * Test page (dev/environment.html, loaded by tests/e2e/environment.spec.ts): draws a mirror ball lit only by the
 * studio environment (src/render/environment.ts), seen from +z with an orthographic camera, and compares each
 * pixel's brightness with the studio's radiance in the direction that pixel reflects, computed here from the
 * same function: the correlation is high only if three.js samples the map the way it was written (cube face
 * order, rows, the x mirror of cube textures). The mirrored studio's correlation is reported beside it.
 * Not part of the app.
 */
import * as THREE from 'three';
import { studioEnvironment, studioRadiance } from '../src/render/environment';

function correlation(a: number[], b: number[]): number {
  const n = a.length;
  const ma = a.reduce((s, x) => s + x, 0) / n, mb = b.reduce((s, x) => s + x, 0) / n;
  let ab = 0, aa = 0, bb = 0;
  for (let i = 0; i < n; i++) {
    ab += (a[i] - ma) * (b[i] - mb);
    aa += (a[i] - ma) ** 2;
    bb += (b[i] - mb) ** 2;
  }
  return ab / Math.sqrt(aa * bb);
}

function main(): Record<string, unknown> {
  const canvas = document.querySelector<HTMLCanvasElement>('#ball')!;
  const size = canvas.width;
  const renderer = new THREE.WebGLRenderer({ canvas, antialias: false, preserveDrawingBuffer: true });
  renderer.toneMapping = THREE.NoToneMapping;
  renderer.outputColorSpace = THREE.LinearSRGBColorSpace;
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0, 0, 0);
  const environment = studioEnvironment();
  const ball = new THREE.Mesh(
    new THREE.SphereGeometry(1, 128, 64),
    new THREE.MeshStandardMaterial({ color: 0xffffff, metalness: 1, roughness: 0, envMap: environment }),
  );
  scene.add(ball);
  const camera = new THREE.OrthographicCamera(-1, 1, 1, -1, 0.1, 10);
  camera.position.set(0, 0, 5);
  renderer.render(scene, camera);
  const gl = renderer.getContext();
  const pixels = new Uint8Array(size * size * 4);
  gl.readPixels(0, 0, size, size, gl.RGBA, gl.UNSIGNED_BYTE, pixels);
  const shown: number[] = [], expected: number[] = [], mirrored: number[] = [];
  const c = [0, 0, 0];
  const luminance = (r: number, g: number, b: number) => 0.2126 * r + 0.7152 * g + 0.0722 * b;
  for (let py = 0; py < size; py++) {
    for (let px = 0; px < size; px++) {
      // readPixels' row 0 is the bottom: y grows upwards as in the scene.
      const x = (2 * (px + 0.5)) / size - 1, y = (2 * (py + 0.5)) / size - 1;
      const rr = x * x + y * y;
      if (rr > 0.85) continue; // the rim, where the sphere's facets and the reflection's grazing angle blur it
      const n = [x, y, Math.sqrt(1 - rr)];
      // The view direction is +z: r = 2 (n.v) n - v.
      const r = [2 * n[2] * n[0], 2 * n[2] * n[1], 2 * n[2] * n[2] - 1];
      const at = 4 * (py * size + px);
      shown.push(luminance(pixels[at], pixels[at + 1], pixels[at + 2]) / 255);
      studioRadiance(r[0], r[1], r[2], c);
      expected.push(Math.min(1, luminance(c[0], c[1], c[2])));
      studioRadiance(-r[0], r[1], r[2], c);
      mirrored.push(Math.min(1, luminance(c[0], c[1], c[2])));
    }
  }
  environment.dispose();
  renderer.dispose();
  return { pixels: shown.length, correlation: correlation(shown, expected), mirroredCorrelation: correlation(shown, mirrored) };
}

try {
  Object.assign(globalThis, { environmentResult: main() });
} catch (e) {
  Object.assign(globalThis, { environmentResult: { error: (e as Error).message } });
}
