/** The demo's exports of a take: a .glb with morph-target animation, or the raw float32 frames. */
import type { Animation } from '../engine/engine';
import type { FaceTemplate } from '../template/face-template';
import { exportGlb, rawFrames, download, GLB_COMPONENTS, GLB_EXACT_FRAMES } from './export-glb';
import { showStatus, tell, ui } from './controls';

export async function exportGlbFile(animation: Animation, name: string, template: FaceTemplate, unitsPerMm: number): Promise<void> {
  // Busy, not disabled: a disabled button would drop the keyboard focus.
  if (ui.exportGlbButton.getAttribute('aria-busy') === 'true') return;
  ui.exportGlbButton.setAttribute('aria-busy', 'true');
  try {
    if (animation.frames > GLB_EXACT_FRAMES) {
      showStatus(`Preparing the .glb: finding the clip's ${GLB_COMPONENTS} strongest motion components…`);
      await new Promise((r) => setTimeout(r, 30)); // let the message show before the work
    }
    const glb = await exportGlb(animation, template, unitsPerMm);
    const file = `${name.replace(/\.[^.]+$/, '')}.glb`;
    download(new Blob([glb.bytes], { type: 'model/gltf-binary' }), file);
    tell(`Saved ${file}: the animation as a glTF model.`);
    ui.exportInfo.textContent = (`Exported ${glb.frames} frames as .glb (${(glb.bytes.byteLength / 1e6).toFixed(1)} MB)` +
      (glb.encoding === 'components'
        ? `: the clip is longer than ${GLB_EXACT_FRAMES} frames, so its motion is ${glb.morphTargets} morph targets with per-frame weights ` +
          `(largest deviation from the exact frames: ${glb.maxErrorMm.toFixed(2)} mm).`
        : ', one morph target per frame.'));
  } catch (err) {
    tell(`Export failed: ${(err as Error).message}`, true);
  } finally {
    ui.exportGlbButton.removeAttribute('aria-busy');
  }
}

export function exportRawFile(animation: Animation, name: string, template: FaceTemplate): void {
  const n = template.vertexCount;
  const file = `${name.replace(/\.[^.]+$/, '')}.${animation.frames}x${n}x3.f32`;
  download(rawFrames(animation), file);
  tell(`Saved ${file}: the raw frames.`);
  ui.exportInfo.textContent = (`Exported ${animation.frames} frames x ${n} vertices x 3 as float32 (little-endian, ${template.units}, ${animation.fps} fps).`);
}
