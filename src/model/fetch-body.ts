/**
 * A download that cannot hang: the body of a URL, or a rejection once nothing has arrived for a while (neither the
 * response's headers nor the next bytes of its body). A slow download that keeps coming is waited for. Every file
 * the page or the element fetches goes through it (the manifest, the template, the model files, an avatar, speak()'s
 * audio URL), so a stalled connection ends in a message instead of "Loading…" forever.
 */

/** Seconds a download may bring nothing before it fails (the default of every `stallSeconds`). */
export const STALL_SECONDS = 30;

/** The longest a browser timer waits (about 24.8 days); a longer stallSeconds is as Infinity: never. */
const MAX_TIMER_MS = 2 ** 31 - 1;

/** `stallSeconds` if it is a positive number of seconds (Infinity: a download never fails for bringing nothing), else a RangeError. */
export function checkedStallSeconds(seconds: unknown): number {
  if (typeof seconds === 'number' && seconds > 0) return seconds;
  throw new RangeError(`stallSeconds must be a positive number of seconds (Infinity: downloads never time out), not ${String(seconds)}`);
}

/** Nothing arrived for `stallSeconds`; the message says so and what to do, for the caller to name what was being fetched. */
export class StalledError extends Error {
  override name = 'StalledError';
}

export interface FetchedBody {
  ok: boolean;
  status: number;
  /** The body (empty where the response is not ok: it is not read). */
  bytes: ArrayBuffer;
}

export interface FetchBodyOptions {
  fetch?: typeof fetch;
  stallSeconds?: number;
  /** Cancels the download: it rejects with the signal's reason at once. */
  signal?: AbortSignal;
}

/** The response to `url` and its whole body; StalledError once nothing has arrived for `stallSeconds`; fetch's own errors as they are; a RangeError for a stallSeconds that is no positive number. */
export async function fetchBody(url: string | URL, options: FetchBodyOptions = {}): Promise<FetchedBody> {
  options.signal?.throwIfAborted();
  const fetchFn = options.fetch ?? fetch.bind(globalThis);
  const seconds = checkedStallSeconds(options.stallSeconds ?? STALL_SECONDS);
  const abort = new AbortController();
  const arm = () => (seconds * 1000 <= MAX_TIMER_MS ? setTimeout(() => abort.abort(), seconds * 1000) : undefined); // (longer: never)
  let timer = arm();
  const alive = () => {
    clearTimeout(timer);
    timer = arm();
  };
  const said = `nothing arrived for ${seconds} s; check the connection and try again`;
  const stalled = new Promise<never>((_, reject) => abort.signal.addEventListener('abort', () => reject(new StalledError(said)), { once: true }));
  stalled.catch(() => undefined); // deliberate: read in the races below, or never needed once the body is in
  const cancel = (): void => abort.abort(); // (the races then end, and the catch gives the caller's reason)
  options.signal?.addEventListener('abort', cancel, { once: true });
  try {
    // A fetch that ignores the signal (a page's own fetch function) still cannot hang: the race ends it.
    const r = await Promise.race([fetchFn(url, { signal: abort.signal }), stalled]);
    if (!r.ok) return { ok: false, status: r.status, bytes: new ArrayBuffer(0) };
    alive();
    if (!r.body) return { ok: true, status: r.status, bytes: await Promise.race([r.arrayBuffer(), stalled]) };
    const reader = r.body.getReader();
    const chunks: Uint8Array[] = [];
    let length = 0;
    for (;;) {
      const { done, value } = await Promise.race([reader.read(), stalled]);
      if (done) break;
      alive();
      chunks.push(value);
      length += value.length;
    }
    const bytes = new Uint8Array(length);
    let o = 0;
    for (const c of chunks) bytes.set(c, (o += c.length) - c.length);
    return { ok: true, status: r.status, bytes: bytes.buffer };
  } catch (e) {
    if (options.signal?.aborted) throw options.signal.reason;
    throw abort.signal.aborted ? new StalledError(said) : e;
  } finally {
    clearTimeout(timer);
    options.signal?.removeEventListener('abort', cancel);
  }
}
