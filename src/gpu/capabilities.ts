/**
 * The one place that asks what the browser's GPU can do. Everything that
 * wants WebGPU goes through here, so a missing adapter is decided once and
 * reported the same way everywhere.
 */

export interface WebGPUSupport {
  available: boolean;
  /** Human-readable: "google swiftshader (fallback adapter)" or why there is none. */
  description: string;
  adapter: GPUAdapter | null;
  info: { vendor: string; architecture: string; device: string; isFallbackAdapter: boolean } | null;
}

let cached: Promise<WebGPUSupport> | null = null;

/**
 * How long the browser may take to answer for an adapter before the page goes on without WebGPU (the spec lets it
 * wait). Generous: a software GPU still busy with the page before (SwiftShader after a WebGPU animation) took 15 s.
 */
const ADAPTER_WAIT_MS = 60_000;

/** A hardware adapter: what 'auto' chooses WebGPU for (a software one, SwiftShader, is slower than the CPU path). */
export function isHardwareAdapter(support: WebGPUSupport): boolean {
  return Boolean(support.adapter && !support.info?.isFallbackAdapter);
}

/** Request an adapter once per page; later calls share the answer. */
export function detectWebGPU(): Promise<WebGPUSupport> {
  cached ??= probe();
  return cached;
}

async function probe(): Promise<WebGPUSupport> {
  const gpu = (globalThis.navigator as Navigator | undefined)?.gpu;
  if (!gpu) {
    return { available: false, description: 'no WebGPU in this browser (navigator.gpu is missing)', adapter: null, info: null };
  }
  let adapter: GPUAdapter | null;
  let timer: ReturnType<typeof setTimeout> | undefined;
  try {
    adapter = await Promise.race([gpu.requestAdapter(), new Promise<never>((_, reject) => {
      timer = setTimeout(() => reject(new Error(`no answer within ${ADAPTER_WAIT_MS / 1000} s`)), ADAPTER_WAIT_MS);
    })]);
  } catch (e) {
    return { available: false, description: `WebGPU adapter request failed: ${(e as Error).message}`, adapter: null, info: null };
  } finally {
    clearTimeout(timer);
  }
  if (!adapter) {
    return { available: false, description: 'WebGPU is present but no adapter was found', adapter: null, info: null };
  }
  // GPUAdapter.info came in Chrome 127 (before it, an async requestAdapterInfo()); isFallbackAdapter moved from
  // GPUAdapter to GPUAdapterInfo: read whichever there is.
  const legacy = adapter as GPUAdapter & { isFallbackAdapter?: boolean; requestAdapterInfo?: () => Promise<GPUAdapterInfo> };
  const raw: Partial<GPUAdapterInfo> & { isFallbackAdapter?: boolean } = adapter.info ?? (await legacy.requestAdapterInfo?.().catch(() => undefined)) ?? {}; // (unnamed, then)
  const isFallbackAdapter = Boolean(raw.isFallbackAdapter ?? legacy.isFallbackAdapter);
  const info = { vendor: raw.vendor ?? '', architecture: raw.architecture ?? '', device: raw.device ?? '', isFallbackAdapter };
  const name = [info.vendor, info.architecture, info.device].filter(Boolean).join(' ') || 'unnamed adapter';
  return {
    available: true,
    description: `${name}${isFallbackAdapter ? ' (fallback adapter, software)' : ''}`,
    adapter,
    info,
  };
}

let sharedDevice: Promise<GPUDevice> | null = null;

/**
 * The page's one GPUDevice (an adapter can create only one), shared by every decoder. After the device
 * is lost, the next call probes for a new adapter and device.
 */
export function requestSharedDevice(): Promise<GPUDevice> {
  sharedDevice ??= (async () => {
    const support = await detectWebGPU();
    if (!support.adapter) throw new Error(support.description);
    const device = await support.adapter.requestDevice({ label: 'talkingFace.device' });
    device.lost.then(() => {
      sharedDevice = null;
      cached = null;
    });
    return device;
  })();
  // Forget a failed request so the next call tries again; the caller receives the error through the returned promise.
  sharedDevice.catch(() => {
    sharedDevice = null;
  });
  return sharedDevice;
}
