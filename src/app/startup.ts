/**
 * What the demo loads first, all at once: the manifest, then the face's template and the model side by side (each ONNX
 * session created as soon as its file is in: engine.ts), and what WebGPU the browser offers.
 */
import { loadTemplate, type FaceTemplate } from '../template/face-template';
import { detectWebGPU, type WebGPUSupport } from '../gpu/capabilities';
import { TalkingFaceEngine } from '../engine/engine';
import { DEFAULT_TEMPLATE_URL, fetchManifest, templateUrlOf } from '../model/artefacts';

/** How long the face, once its template is in, waits for the model's files to reach onnxruntime. */
const FACE_WAITS_MS = 300;

export interface Startup {
  /** The model (rejects with why it cannot be loaded; that rejection is handled here: read it with await). */
  engine: Promise<TalkingFaceEngine>;
  /** The template and WebGPU, once the face may be built (the default template where the manifest failed). */
  face: Promise<{ template: FaceTemplate; gpu: WebGPUSupport }>;
}

export function startLoading(): Startup {
  const gpuReady = detectWebGPU();
  const manifest = fetchManifest(undefined).catch((e: Error) => e);
  const template = manifest.then((m) => loadTemplate(m instanceof Error ? DEFAULT_TEMPLATE_URL : templateUrlOf(m.manifest, m.manifestUrl)));
  const engine = manifest.then((m) => {
    if (m instanceof Error) throw m;
    return TalkingFaceEngine.load({ ...m, template });
  });
  const engineSettled = engine.catch(() => undefined); // (a failure is read by whoever awaits `engine`)
  // Building and drawing the face holds the main thread for most of a second under a software GPU (issue 18): the
  // model's sessions are handed to onnxruntime's worker first, which creates them meanwhile (a failed load does not
  // hold the face back, nor do files still on their way after FACE_WAITS_MS: on a slow connection the face comes first).
  const face = Promise.all([template, gpuReady]).then(async ([t, gpu]) => {
    const waited = new Promise((resolve) => setTimeout(resolve, FACE_WAITS_MS));
    await Promise.race([TalkingFaceEngine.sessionsRequested, engineSettled, waited]);
    return { template: t, gpu };
  });
  return { engine, face };
}
