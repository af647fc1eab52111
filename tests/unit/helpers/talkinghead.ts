/**
 * TalkingHead (@met4citizen/talkinghead, a devDependency) in Node, for the unit tests: made in its avatarOnly mode
 * (no WebGL renderer, no requestAnimationFrame: the test steps `head.animate(ms)` itself), with stand-ins for
 * what its constructor and loader touch of the browser: Web Audio (it builds its audio graph up front) and
 * ProgressEvent (three's FileLoader). Avatars are handed to it as data: URLs, which Node's fetch reads.
 */
import { readFileSync } from 'node:fs';
import { resolve } from 'node:path';
import type { TalkingHead } from '@met4citizen/talkinghead';
import { ROOT } from './exported';

/**
 * A Web Audio node, param or buffer that accepts anything: every property read is another such stand-in, every
 * call returns one, every write is kept. Enough for an audio graph nobody listens to.
 */
function anything(): unknown {
  const kept: Record<PropertyKey, unknown> = {};
  return new Proxy(function () {}, {
    get: (_, key) => (key in kept ? kept[key] : typeof key === 'symbol' || key === 'then' ? undefined : (kept[key] = anything())),
    set: (_, key, value) => ((kept[key] = value), true),
    apply: () => anything(),
  });
}

class AudioContextStandIn {
  currentTime = 0;
  state = 'running';
  sampleRate = 48000;
  constructor() {
    return new Proxy(this, { get: (target, key) => (key in target ? target[key as keyof AudioContextStandIn] : typeof key === 'symbol' ? undefined : anything()) });
  }
}

/** A TalkingHead instance in avatarOnly mode; `options` add to (or override) its options. */
export async function talkingHeadInNode(options: Record<string, unknown> = {}): Promise<TalkingHead> {
  const g = globalThis as Record<string, unknown>;
  g.AudioContext ??= AudioContextStandIn;
  g.ProgressEvent ??= class extends Event {
    constructor(type: string, init: object = {}) {
      super(type);
      Object.assign(this, init);
    }
  };
  const { TalkingHead } = await import('@met4citizen/talkinghead');
  return new TalkingHead(null, { avatarOnly: true, lipsyncModules: [], cameraView: 'head', ...options });
}

/** An examples/avatars file as a data: URL. */
export function avatarUrl(file: string): string {
  return `data:model/gltf-binary;base64,${readFileSync(resolve(ROOT, 'examples/avatars', file)).toString('base64')}`;
}
