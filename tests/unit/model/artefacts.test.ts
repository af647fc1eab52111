/** fetchArtefacts (src/model/artefacts.ts): the manifest first, then every file on its own promise, each checked. */
import { readFileSync } from 'node:fs';
import { resolve } from 'node:path';
import { describe, expect, it } from 'vitest';
import { fetchArtefacts, fetchManifest, ModelLoadError } from '../../../src/model/artefacts';
import { checkManifest, ManifestError } from '../../../src/model/manifest';

const MODELS = resolve(import.meta.dirname, '../../../models');

/** A fetch that serves models/ from disk, with `corrupt` paths answered by other bytes. */
function diskFetch(corrupt: string[] = []): typeof fetch {
  return (async (input: RequestInfo | URL) => {
    const path = new URL(String(input)).pathname.replace(/^\/models\//, '');
    const bytes = corrupt.includes(path) ? Buffer.from('not the file') : readFileSync(resolve(MODELS, path));
    return new Response(bytes);
  }) as typeof fetch;
}

const manifestUrl = 'http://test/models/manifest.json';

describe('fetchArtefacts', () => {
  it('hands each runtime file over on its own promise, checked against its SHA-256', async () => {
    const a = await fetchArtefacts({ manifestUrl, fetch: diskFetch() });
    expect(Object.keys(a.files).sort()).toEqual([...a.manifest.runtime_files].sort());
    const pose = await a.files.pose_conv;
    expect(pose.byteLength).toBe(readFileSync(resolve(MODELS, a.manifest.files.pose_conv)).length);
    expect((await a.template).id).toBe(a.manifest.template.id);
    await Promise.all(Object.values(a.files));
  });

  it('refuses a manifest of another version, saying to re-export (version 1 made the tokens in hierarchical.onnx)', () => {
    const manifest = JSON.parse(readFileSync(resolve(MODELS, 'manifest.json'), 'utf8'));
    expect(checkManifest(manifest).version).toBe(2);
    expect(() => checkManifest({ ...manifest, version: 1 })).toThrow(ManifestError);
    expect(() => checkManifest({ ...manifest, version: 1 })).toThrow(/version 1 is not supported by this build \(2\): re-export/);
  });

  it('refuses a manifest that lacks what the browser loads, saying what (not "corrupt", nor a TypeError later)', () => {
    const manifest = JSON.parse(readFileSync(resolve(MODELS, 'manifest.json'), 'utf8'));
    const without = (path: string[]) => {
      const m = structuredClone(manifest);
      let at = m;
      for (const key of path.slice(0, -1)) at = at[key];
      delete at[path.at(-1)!];
      return m;
    };
    expect(() => checkManifest(without(['sha256', 'pose_lstm']))).toThrow(/lacks pose_lstm in runtime_files, files or sha256/);
    expect(() => checkManifest(without(['files', 'decoder_weights']))).toThrow(/lacks decoder_weights in runtime_files, files or sha256/);
    expect(() => checkManifest(without(['runtime_files']))).toThrow(/lacks content_encoder, hierarchical, pose_conv, pose_lstm, decoder_weights in runtime_files/);
    expect(() => checkManifest(without(['audio', 'feature_rate']))).toThrow(/lacks audio\.feature_rate/);
    expect(() => checkManifest(without(['model', 'config', 'window']))).toThrow(/lacks model\.config\.window/);
  });

  it('rejects only the corrupt file, with a message that names it', async () => {
    const manifest = JSON.parse(readFileSync(resolve(MODELS, 'manifest.json'), 'utf8'));
    const a = await fetchArtefacts({ manifestUrl, fetch: diskFetch([manifest.files.hierarchical]) });
    await expect(a.files.hierarchical).rejects.toThrow(ModelLoadError);
    await expect(a.files.hierarchical).rejects.toThrow(/hierarchical.*SHA-256/);
    await expect(a.files.content_encoder).resolves.toBeInstanceOf(ArrayBuffer);
    await Promise.allSettled([a.template, ...Object.values(a.files)]);
  });

  it('refuses a template the model was not trained on', async () => {
    const a = await fetchArtefacts({ manifestUrl, fetch: diskFetch() });
    const other = { ...(await a.template), id: 'someone-else' };
    const b = await fetchArtefacts({ manifestUrl, fetch: diskFetch(), template: Promise.resolve(other) });
    await expect(b.template).rejects.toThrow(/trained on the face template/);
    await Promise.allSettled([...Object.values(a.files), ...Object.values(b.files)]);
  });
});

describe('a stalled download', () => {
  it('fails naming the file once nothing has arrived for stallSeconds; a slow one that keeps coming is waited for', async () => {
    const stalling = (file: string, trickle: boolean): typeof fetch => (async (input: RequestInfo | URL, init?: RequestInit) => {
      const url = String(input);
      if (!url.endsWith(file)) return diskFetch()(input, init);
      const bytes = new Uint8Array(await (await diskFetch()(input)).arrayBuffer());
      let sent = 0;
      return new Response(new ReadableStream({
        async pull(c) {
          if (!trickle && sent > 0) return new Promise<void>(() => undefined); // a first chunk, then nothing
          await new Promise((r) => setTimeout(r, trickle ? 20 : 0));
          const n = Math.min(bytes.length - sent, trickle ? Math.ceil(bytes.length / 8) : 1000);
          c.enqueue(bytes.slice(sent, (sent += n)));
          if (sent >= bytes.length) c.close();
        },
      }));
    }) as typeof fetch;
    const file = JSON.parse(readFileSync(resolve(MODELS, 'manifest.json'), 'utf8')).files.hierarchical as string;
    const stalled = await fetchArtefacts({ manifestUrl, fetch: stalling(file, false), stallSeconds: 0.15 });
    await expect(stalled.files.hierarchical).rejects.toThrow(new RegExp(`model file ${file} stalled: nothing arrived for 0.15 s`));
    await Promise.allSettled([stalled.template, ...Object.values(stalled.files)]);
    const slow = await fetchArtefacts({ manifestUrl, fetch: stalling(file, true), stallSeconds: 0.15 });
    expect((await slow.files.hierarchical).byteLength).toBeGreaterThan(1000); // 8 pieces 20 ms apart: 160 ms in all
    await Promise.allSettled([slow.template, ...Object.values(slow.files)]);
  });
});

describe('fetchManifest of a wrong URL', () => {
  it('says an HTML page came back instead of the manifest, as hosts answer a missing file', async () => {
    const page = (async () => new Response('<!doctype html><html><body>app</body></html>')) as typeof fetch;
    await expect(fetchManifest('http://test/models/manifest.json', page)).rejects.toThrow(/is an HTML page, not the manifest: no manifest\.json there/);
  });
});
