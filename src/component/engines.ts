/**
 * The engines <talking-face> elements share: one per model, template and backend (its runs are serialised). Each
 * element holds the engine it uses; ENGINE_LINGER_MS after the last hold is released (every element using it
 * removed from the page, or switched to another model or backend) the engine is disposed: its sessions, workers
 * and buffers freed. An element put back within that time (moved in the page, a route shown again) takes it back.
 */
import { TalkingFaceEngine, type Backend } from '../engine/engine';

/** How long an engine that no element holds is kept before it is disposed (ms). */
export const ENGINE_LINGER_MS = 10_000;

interface Shared {
  engine: Promise<TalkingFaceEngine>;
  holds: number;
  linger: ReturnType<typeof setTimeout> | null;
}

const engines = new Map<string, Shared>();

/** An element's hold on a shared engine. */
export interface EngineHold {
  engine: Promise<TalkingFaceEngine>;
  /** The element no longer uses it (once is enough). */
  release(): void;
}

export function holdEngine(model: string, template: string | null, backend: string): EngineHold {
  const key = `${model}|${template ?? ''}|${backend}`;
  let shared = engines.get(key);
  if (!shared) {
    const engine = TalkingFaceEngine.load({ manifestUrl: model, templateUrl: template ?? undefined, backend: backend as 'auto' | Backend });
    const entry: Shared = (shared = { engine, holds: 0, linger: null });
    engines.set(key, entry);
    // Forget a failed load so a later element can retry it; the failure itself reaches the caller through `engine`.
    engine.catch(() => engines.get(key) === entry && engines.delete(key));
  }
  const entry = shared;
  if (entry.linger !== null) clearTimeout(entry.linger);
  entry.linger = null;
  entry.holds++;
  let held = true;
  return {
    engine: entry.engine,
    release: () => {
      if (!held) return;
      held = false;
      if (--entry.holds > 0 || engines.get(key) !== entry) return;
      entry.linger = setTimeout(() => {
        if (engines.get(key) === entry) engines.delete(key); // (its load failed meanwhile: another may hold the key now)
        void entry.engine.then((e) => e.dispose(), () => undefined); // a failed load holds nothing
      }, ENGINE_LINGER_MS);
    },
  };
}

/** What `work` gives, or null as soon as `signal` is aborted (stop() while the model loads: the caller then does nothing). */
export function unlessAborted<T>(work: Promise<T>, signal: AbortSignal): Promise<T | null> {
  const stopped = new Promise<null>((resolve) => (signal.aborted ? resolve(null) : signal.addEventListener('abort', () => resolve(null), { once: true })));
  return Promise.race([work.catch((e: unknown) => (signal.aborted ? null : Promise.reject(e))), stopped]);
}
