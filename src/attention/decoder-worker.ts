/**
 * A Web Worker running the fast CPU decoder (fast-decoder.ts) on the frames it is sent. DecoderPool
 * (decoder-pool.ts) starts one per spare core and splits each chunk's frames between them.
 */
import { FastDecoder } from './fast-decoder';
import type { DecoderWeights } from './reference';
import type { ModelConstants } from '../model/manifest';
import type { Adjacency } from '../template/mesh-topology';

interface Init {
  type: 'init';
  weights: DecoderWeights;
  adjacency: Adjacency;
  constants: ModelConstants;
}

interface Job {
  type: 'decode';
  id: number;
  latents: Float32Array;
  poseToken: Float32Array;
  frames: number;
}

let decoder: FastDecoder | null = null;

self.onmessage = (e: MessageEvent<Init | Job>) => {
  const msg = e.data;
  try {
    if (msg.type === 'init') {
      decoder = new FastDecoder(msg.weights, msg.adjacency, msg.constants);
      self.postMessage({ type: 'ready', kernel: decoder.kernelName });
      return;
    }
    if (!decoder) throw new Error('decoder worker: decode before init');
    const out = decoder.decodeLatents(msg.latents, msg.poseToken, msg.frames);
    (self as unknown as Worker).postMessage({ type: 'done', id: msg.id, offsets: out.offsets, pose: out.pose }, [out.offsets.buffer, out.pose.buffer]);
  } catch (err) {
    self.postMessage({ type: 'error', id: (msg as Job).id ?? -1, message: (err as Error).message });
  }
};
