/** The engines <talking-face> elements share: one per model, template and backend (its runs are serialised). */
import { TalkingFaceEngine, type Backend } from '../engine/engine';

const engines = new Map<string, Promise<TalkingFaceEngine>>();

export function sharedEngine(model: string, template: string | null, backend: string): Promise<TalkingFaceEngine> {
  const key = `${model}|${template ?? ''}|${backend}`;
  let p = engines.get(key);
  if (!p) {
    p = TalkingFaceEngine.load({ manifestUrl: model, templateUrl: template ?? undefined, backend: backend as 'auto' | Backend });
    engines.set(key, p);
    // Forget a failed load so a later element can retry it; the failure itself reaches the caller through `p`.
    p.catch(() => engines.delete(key));
  }
  return p;
}
