/**
 * The render benchmark (part of dev/bench.ts, driven by `npm run bench`): the whole head (src/render/) drawn for
 * frames of a real animation, with its idle life on. Per frame, in ms:
 * - head_update_ms: main-thread work to pose the head for a frame: the speech blend and blink, the jaw estimate,
 *   the shell and mouth cavity following the face, normals over face + shell + cavity, tongue, eyes, breathing;
 * - face_normals_ms: what the face alone cost before (its normals), so extra_geometry_ms = the difference is what
 *   the head adds on the CPU;
 * - render_call_ms: renderer.render() on the main thread (issuing the draw calls, not waiting for the GPU);
 * - main_thread_ms: head_update_ms + render_call_ms (the budget: under 2 ms);
 * - frame_ms: a whole frame including the GPU's work (a 1-pixel readback waits for it). Here the "GPU" is
 *   SwiftShader on the CPU, so this is a software-rendering figure, not a GPU one.
 */
import * as THREE from 'three';
import { FaceView } from '../src/render/face-view';
import type { TalkingFaceEngine } from '../src/engine/engine';

export async function renderBench(engine: TalkingFaceEngine, speech: Float32Array, width = 640, height = 480): Promise<Record<string, number>> {
  const canvas = document.createElement('canvas');
  canvas.style.cssText = `width:${width}px;height:${height}px;display:block`;
  document.body.append(canvas);
  const view = new FaceView(canvas, engine.template);
  try {
    await new Promise((r) => requestAnimationFrame(r)); // let the resize observer size the canvas
    view.setRestFace(await engine.restFace());
    const a = await engine.animate(speech, { unposed: true });
    const n3 = engine.template.vertexCount * 3;
    const frames = Math.min(a.frames, 90);
    const gl = view.renderer.getContext();
    const pixel = new Uint8Array(4);
    const face = new THREE.BufferGeometry();
    const facePositions = new THREE.BufferAttribute(new Float32Array(n3), 3);
    face.setAttribute('position', facePositions);
    face.setIndex(new THREE.BufferAttribute(engine.template.triangles, 1));
    const sums = { head_update_ms: 0, face_normals_ms: 0, render_call_ms: 0, frame_ms: 0 };
    view.setSpeaking(true);
    const t0 = performance.now() / 1000;
    for (let k = -5; k < frames; k++) { // five warm-up frames (shader compilation)
      const f = Math.max(0, k);
      const unposed = a.unposed!.subarray(f * n3, (f + 1) * n3);
      let t = performance.now();
      view.setTongue(a.tongue[f]);
      view.setVertices(unposed);
      view.update(t0 + f / a.fps);
      const update = performance.now() - t;
      t = performance.now();
      (facePositions.array as Float32Array).set(unposed);
      face.computeVertexNormals();
      const normals = performance.now() - t;
      t = performance.now();
      view.renderer.render(view.scene, view.camera);
      const call = performance.now() - t;
      gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, pixel);
      const whole = performance.now() - t + update;
      if (k < 0) continue;
      sums.head_update_ms += update;
      sums.face_normals_ms += normals;
      sums.render_call_ms += call;
      sums.frame_ms += whole;
    }
    face.dispose();
    const per = Object.fromEntries(Object.entries(sums).map(([k, v]) => [k, v / frames])) as typeof sums;
    const info = view.renderer.info.render;
    return {
      ...per,
      extra_geometry_ms: per.head_update_ms - per.face_normals_ms,
      main_thread_ms: per.head_update_ms + per.render_call_ms,
      frames, width, height,
      skin_vertices: view.model.vertices.length / 3,
      triangles: info.triangles,
      draw_calls: info.calls,
    };
  } finally {
    view.dispose();
    canvas.remove();
  }
}
