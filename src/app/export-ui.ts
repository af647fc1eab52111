/** The demo's exports of a take: a video of it playing, a .glb with morph-target animation, or the raw float32 frames. */
import type { Animation } from '../engine/engine';
import type { FaceTemplate } from '../template/face-template';
import { exportGlb, rawFrames, download, GLB_EXACT_FRAMES } from './export-glb';
import { showStatus, tell, ui } from './controls';
import { fileBaseName, isolated } from './names';
import { PlaybackStopped, recordTake, videoType } from '../player/record-video';
import type { Player } from '../player/player';

/** The .glb or video being prepared (a long clip's takes seconds, a video as long as the take): Escape cancels it (cancelExport). */
let exporting: AbortController | null = null;

/** Cancel a .glb being prepared; true if there was one. */
export function cancelExport(): boolean {
  exporting?.abort();
  return exporting !== null;
}

export async function exportGlbFile(animation: Animation, name: string, template: FaceTemplate, unitsPerMm: number): Promise<void> {
  // Busy, not disabled: a disabled button would drop the keyboard focus.
  if (exporting) {
    if (ui.exportVideoButton.getAttribute('aria-busy')) tell('A video of the take is being recorded: wait for it, or press Escape to cancel it.');
    return;
  }
  const controller = (exporting = new AbortController());
  ui.exportGlbButton.setAttribute('aria-busy', 'true');
  try {
    const preparing = `Preparing the .glb of ${animation.frames} frames`;
    if (animation.frames > GLB_EXACT_FRAMES) showStatus(`${preparing}… (Escape cancels)`);
    const glb = await exportGlb(animation, template, unitsPerMm, undefined, {
      signal: controller.signal,
      onProgress: (done) => showStatus(`${preparing}: ${Math.round(100 * done)}%… (Escape cancels)`),
    });
    const file = `${fileBaseName(name)}.glb`;
    download(new Blob([glb.bytes], { type: 'model/gltf-binary' }), file);
    tell(`Saved ${isolated(file)}: the animation as a glTF model.`);
    ui.exportInfo.textContent = (`Exported ${glb.frames} frames as .glb (${(glb.bytes.byteLength / 1e6).toFixed(1)} MB)` +
      (glb.encoding === 'components'
        ? `: the clip is longer than ${GLB_EXACT_FRAMES} frames, so its motion is ${glb.morphTargets} morph targets with per-frame weights ` +
          `(largest deviation from the exact frames: ${glb.maxErrorMm.toFixed(2)} mm).`
        : ', one morph target per frame.'));
  } catch (err) {
    if (controller.signal.aborted) tell('Export cancelled.');
    else tell(`Export failed: ${(err as Error).message}`, true);
  } finally {
    exporting = null;
    ui.exportGlbButton.removeAttribute('aria-busy');
  }
}

export function exportRawFile(animation: Animation, name: string, template: FaceTemplate): void {
  const n = template.vertexCount;
  const file = `${fileBaseName(name)}.${animation.frames}x${n}x3.f32`;
  download(rawFrames(animation), file);
  tell(`Saved ${isolated(file)}: the raw frames.`);
  ui.exportInfo.textContent = (`Exported ${animation.frames} frames x ${n} vertices x 3 as float32 (little-endian, ${template.units}, ${animation.fps} fps).`);
}

/** Record the take playing, with its sound, and save it (player/record-video.ts); the button again or Escape cancels. */
export async function exportVideoFile(view: { recording: boolean }, player: Player, fps: number, name: string): Promise<void> {
  if (exporting) {
    if (ui.exportVideoButton.getAttribute('aria-busy')) exporting.abort(); // the button again: cancel
    else tell('A .glb of the take is being prepared: wait for it, or press Escape to cancel it.');
    return;
  }
  const type = videoType();
  if (!type) return tell('This browser cannot record video (it has no MediaRecorder for WebM or MP4): export a .glb instead.', true);
  const controller = (exporting = new AbortController());
  const frames = player.take?.frames ?? 0;
  ui.exportVideoButton.setAttribute('aria-busy', 'true');
  ui.playButton.textContent = 'Pause'; // the take plays for the video (Pause stops both)
  try {
    const seconds = (frames / fps).toFixed(1);
    ui.canvas.scrollIntoView({ block: 'nearest' }); // what is recorded, in sight
    const video = await recordTake(ui.canvas, view, player, fps, controller.signal,
      (f) => showStatus(`Recording the video: ${(f / fps).toFixed(1)} of ${seconds} s… (Escape or Export video again cancels)`));
    const file = `${fileBaseName(name)}.${type.startsWith('video/mp4') ? 'mp4' : 'webm'}`;
    download(video, file);
    tell(`Saved ${isolated(file)}: the take as a video with its sound.`);
    ui.exportInfo.textContent = `Exported a video of the ${seconds} s take and the face going back to rest (${type}, ${(video.size / 1e6).toFixed(1)} MB): the face as shown, with the take's sound.`;
  } catch (err) {
    if (controller.signal.aborted) tell('Video cancelled.');
    else if (err instanceof PlaybackStopped) tell(`Video stopped: ${err.message}.`);
    else tell(`The video could not be made: ${(err as Error).message}`, true);
  } finally {
    exporting = null;
    ui.exportVideoButton.removeAttribute('aria-busy');
    ui.playButton.textContent = player.isPlaying ? 'Pause' : 'Play';
  }
}
