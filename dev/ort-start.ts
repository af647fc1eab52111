/**
 * Test page (dev/ort-start.html, measured by npm run bench): onnxruntime-web alone, started as the engine starts it
 * (its worker, the runtime's WebAssembly, the encoders' four sessions from the model's files) with nothing else on
 * the page: no face to build or draw, no attention decoder. Its time to ready is the floor under the demo's
 * (issue 18, docs/results/README.md). Marks body[data-engine] as the demo does. Not part of the app.
 */
import { fetchArtefacts } from '../src/model/artefacts';
import { startOrt, type ExecutionProvider } from '../src/encoders/onnx-model';
import { ContentEncoder } from '../src/encoders/content';
import { PoseEncoder } from '../src/encoders/pose';

async function main(): Promise<void> {
  // As TalkingFaceEngine.load does without a hardware GPU, before any file has arrived; ?stallSeconds=N as load's
  // option; ?providers=webgpu as it does on a hardware GPU (onnxruntime's WebGPU build, in the page), or a list
  // tried in order (webgpu,wasm).
  const query = new URLSearchParams(location.search);
  const stall = query.get('stallSeconds');
  const providers = (query.get('providers') ?? 'wasm').split(',') as ExecutionProvider[];
  startOrt(providers, stall ? Number(stall) : undefined);
  const { manifest, files, template } = await fetchArtefacts();
  void template.catch(() => undefined); // fetched as the engine fetches it, not needed here
  await Promise.all([ContentEncoder.create(manifest, files, providers), PoseEncoder.create(manifest, files, providers)]);
  document.body.dataset.engine = 'ready';
}

main().catch((e: Error) => {
  document.body.dataset.error = e.message;
  document.body.dataset.engine = 'error';
});
