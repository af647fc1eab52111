/**
 * models/manifest.json is the one source of the numbers the browser shares with training. This test fails when
 * one of them is written again as a literal in src/ or shaders/ (code, not comments or strings), so a re-export
 * with another sample rate, fps, class count, template or LayerNorm epsilon cannot silently disagree with the code.
 *
 * Checked: every manifest number that is distinctive enough to mean the manifest's quantity when it appears
 * (not the powers of two and small counts that code uses for other reasons: alignments, workgroups, 1, 2, 3).
 * A hit that means something else is listed in ALLOWED with what it means.
 */
import { describe, expect, it } from 'vitest';
import { readFileSync, readdirSync, statSync } from 'node:fs';
import { join, relative } from 'node:path';
import { ROOT, loadManifest } from '../helpers/exported';

/** file: literal -> what the literal means there. */
const ALLOWED: Record<string, string> = {
  'src/app/export-ui.ts: 30': 'milliseconds to let a status line paint, not frames per second',
  'src/render/face-view.ts: 30': "the camera's vertical field of view in degrees, not frames per second",
  'src/avatar/avatar-view.ts: 30': "the camera's vertical field of view in degrees, as the face view's",
  'src/component/parts.ts: 100': 'CSS percentages, not the feature rate',
  'src/component/parts.ts: 50': "a CSS percentage (the announcer's clip-path), not millimetres",
  'src/avatar/vrm.ts: 100': "VRM 0.x's bind weights (0-100), not the feature rate",
  'src/avatar/vrm-test-avatar.ts: 100': "a VRM 0.x bind's full weight (0-100), not the feature rate",
  'src/model/fetch-body.ts: 30': 'seconds a download may bring nothing (STALL_SECONDS), not frames per second',
  'src/attention/simd/decoder.wat: 80': "byte offsets in a row of attention_d32h4's queries, keys and values, not Mel bands",
  'src/attention/simd/decoder.wat: 160': "byte offsets in a row of attention_d32h4's queries, keys and values, not the hop",
  'src/attention/simd/decoder.wat: 30': 'byte indices of i8x16.shuffle (0 to 31), not frames per second',
};

function files(dir: string, ext: RegExp): string[] {
  return readdirSync(dir).flatMap((name) => {
    const p = join(dir, name);
    return statSync(p).isDirectory() ? files(p, ext) : ext.test(name) ? [p] : [];
  });
}

/** Numeric literals of code lines: comments and string literals removed. */
function literals(text: string): { line: number; token: string }[] {
  const noBlock = text.replace(/\/\*[\s\S]*?\*\//g, (c) => '\n'.repeat(c.split('\n').length - 1));
  return noBlock.split('\n').flatMap((raw, i) => {
    const code = raw.replace(/\/\/.*$/, '').replace(/;;.*$/, '').replace(/'[^']*'|"[^"]*"|`[^`]*`/g, '""');
    return Array.from(code.matchAll(/(?<![\w.$])(\d+(?:\.\d+)?(?:e-?\d+)?)(?![\w.])/g), (m) => ({ line: i + 1, token: m[1] }));
  });
}

function manifestNumbers(): Map<number, string> {
  const m = loadManifest();
  const named: [string, number][] = [
    ...Object.entries(m.audio).filter(([, v]) => typeof v === 'number').map(([k, v]) => [`audio.${k}`, v as number] as [string, number]),
    ...Object.entries(m.model.config).filter(([, v]) => typeof v === 'number').map(([k, v]) => [`model.config.${k}`, v as number] as [string, number]),
    ...Object.entries(m.receptive_field).map(([k, v]) => [`receptive_field.${k}`, v] as [string, number]),
    ['model.layer_norm_eps', m.model.layer_norm_eps],
    ['template.vertices', m.template.vertices],
    ['look_ahead_ms', m.look_ahead_ms],
    ['content_phones.length', m.content_phones.length],
  ];
  const generic = (v: number) => (Number.isInteger(v) && (v < 10 || (v & (v - 1)) === 0)) || v === 0.5 || v === 0.25;
  return new Map(named.filter(([, v]) => !generic(v)).map(([k, v]) => [v, k]));
}

describe('manifest numbers are read, not copied', () => {
  it('no src/ or shaders/ file writes a manifest number as a literal', () => {
    const numbers = manifestNumbers();
    expect(numbers.size).toBeGreaterThan(8); // sample rate, hop, n_mels, fps, classes, eps, vertices, look-back ...
    const sources = [...files(join(ROOT, 'src'), /\.(ts|wat)$/), ...files(join(ROOT, 'shaders'), /\.wgsl$/)]
      .filter((p) => !p.endsWith('-wasm.ts')); // generated from the .wat, which is checked
    const hits: string[] = [];
    for (const p of sources) {
      const rel = relative(ROOT, p);
      for (const { line, token } of literals(readFileSync(p, 'utf8'))) {
        const name = numbers.get(Number(token));
        if (name && !ALLOWED[`${rel}: ${token}`]) hits.push(`${rel}:${line}: ${token} (manifest ${name})`);
      }
    }
    expect(hits, 'read these from the manifest (src/model/manifest.ts), or list them in ALLOWED with their meaning').toEqual([]);
  });

  it('the check sees a copied number: a sample rate written in code is caught, in a comment it is not', () => {
    const found = literals('const rate = 16000; // 16000 Hz\n/* 1e-5 */ const eps = 1e-5;').map((l) => l.token);
    expect(found).toEqual(['16000', '1e-5']);
  });

  it('the manifest URL is written once, as DEFAULT_MANIFEST_URL', () => {
    const uses = files(join(ROOT, 'src'), /\.ts$/).filter((p) => readFileSync(p, 'utf8').includes("'/models/manifest.json'"));
    expect(uses.map((p) => relative(ROOT, p))).toEqual(['src/model/manifest.ts']);
  });
});
