/**
 * Promise.all for the parts of a load that hold resources (ONNX sessions, decoder workers, GPU buffers): where one
 * part fails, the caller gets that failure at once, and every other part is freed as it arrives (its release() or
 * dispose()), so a failed load (a file missing, a hash wrong) leaves nothing running, and a retry starts clean.
 */
type Freeable = { release?: () => unknown; dispose?: () => unknown } | null | undefined;

export function allOrFree<T extends unknown[]>(parts: [...{ [K in keyof T]: Promise<T[K]> }]): Promise<T> {
  const all = Promise.all(parts) as Promise<T>;
  all.catch(() => {
    for (const part of parts) void part.then(free, () => undefined); // (a part that failed holds nothing)
  });
  return all;
}

function free(part: unknown): void {
  const p = part as Freeable;
  const done = p?.release ? p.release() : p?.dispose?.();
  if (done instanceof Promise) done.catch(() => undefined); // deliberate: freeing what a failed load made; nothing to tell
}
