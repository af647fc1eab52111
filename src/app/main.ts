/**
 * The demo shell: the only code that touches the page's DOM. It loads the
 * shipped template, draws it, and reports what the browser can do.
 */
import { loadTemplate } from '../template/face-template';
import { FaceView } from '../render/face-view';
import { detectWebGPU } from '../gpu/capabilities';

const TEMPLATE_URL = '/models/template/template.json';

const status = document.getElementById('status') as HTMLParagraphElement;
const canvas = document.getElementById('face-canvas') as HTMLCanvasElement;

function showStatus(text: string, isError = false): void {
  status.textContent = text;
  status.classList.toggle('error', isError);
}

async function start(): Promise<void> {
  const [template, gpu] = await Promise.all([loadTemplate(TEMPLATE_URL), detectWebGPU()]);
  const view = new FaceView(canvas, template);
  // Exposed for the end-to-end tests and for poking at in the console.
  Object.assign(globalThis, { talkingFace: { view, template, gpu } });
  showStatus(
    `Face: ${template.id} (${template.vertexCount} vertices). ` +
      (gpu.available ? `WebGPU adapter: ${gpu.description}.` : `WebGPU: none (${gpu.description}); the CPU path will be used.`),
  );
  document.body.dataset.ready = 'true';
}

start().catch((e: Error) => {
  showStatus(`Could not start: ${e.message}`, true);
  document.body.dataset.ready = 'error';
  console.error(e);
});
