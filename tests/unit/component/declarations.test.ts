/**
 * The declarations the library ships (tsconfig.lib.json, emitted here into a temporary folder) compile in a strict
 * TypeScript page that installed the package as npm would: its dependencies beside it, plus @types/three, the optional
 * peer docs/embedding.md asks TypeScript users to add; skipLibCheck off, so every shipped .d.ts is checked.
 */
import { execFileSync } from 'node:child_process';
import { cpSync, mkdirSync, mkdtempSync, rmSync, symlinkSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join, resolve } from 'node:path';
import { describe, expect, it } from 'vitest';

const ROOT = resolve(import.meta.dirname, '../../..');
const TSC = join(ROOT, 'node_modules/typescript/bin/tsc');

describe('the shipped declarations', () => {
  it('compile in a strict consumer project with three.js types installed', () => {
    const dir = mkdtempSync(join(tmpdir(), 'consumer-'));
    const pkg = join(dir, 'node_modules/talking-face');
    execFileSync(process.execPath, [TSC, '-p', join(ROOT, 'tsconfig.lib.json'), '--outDir', join(pkg, 'dist/lib/types')], { cwd: ROOT });
    cpSync(join(ROOT, 'package.json'), join(pkg, 'package.json'));
    mkdirSync(join(dir, 'node_modules/@types'));
    for (const dep of ['three', 'onnxruntime-web', '@types/three']) symlinkSync(join(ROOT, 'node_modules', dep), join(dir, 'node_modules', dep));
    writeFileSync(join(dir, 'main.ts'), [
      "import { TalkingFaceElement, type FrameDetail } from 'talking-face';",
      "const face = document.createElement('talking-face') as TalkingFaceElement;",
      "face.addEventListener('frame', (e) => console.log((e as CustomEvent<FrameDetail>).detail.frame));",
      // speakStream(): pieces at a rate, or a MediaStream, never both nor neither; the stream is a type only.
      "import type { SpeechStream, PcmChunk } from 'talking-face';",
      "const speech: SpeechStream = face.speakStream({ sampleRate: 24000, delayMs: 300 });",
      "const piece: PcmChunk = new Int16Array(2400);",
      "const accepted: boolean = speech.write(piece); speech.end(); void speech.done.then(() => accepted);",
      "const followed = face.speakStream({ media: new MediaStream() }); followed.end();",
      "// @ts-expect-error: a MediaStream's stream has no write()",
      "followed.write(piece);",
      "const either = face.speakStream(Math.random() > 0.5 ? { sampleRate: 24000 } : { media: new MediaStream() });",
      "// @ts-expect-error: nor one that may follow a MediaStream",
      "either.write(piece);",
      // speakStream(engine, ...) for a page's own scene: its show() is needed; a MediaStream's has no write() either.
      "import { speakStream, type TalkingFaceEngine, type Frames } from 'talking-face';",
      "declare const engine: TalkingFaceEngine;",
      "const own = speakStream(engine, { sampleRate: 24000, show: (frames: Frames, f: number, speaking: boolean) => void [frames.count, f, speaking] });",
      "own.write(piece); own.stop(); void own.take?.animation.frames;",
      "// @ts-expect-error: show is needed",
      "speakStream(engine, { sampleRate: 24000 });",
      "// @ts-expect-error: no write() on a MediaStream's",
      "speakStream(engine, { media: new MediaStream(), show: () => undefined }).write(piece);",
      "// @ts-expect-error: a rate or a MediaStream is needed",
      "face.speakStream({});",
      "// @ts-expect-error: not both",
      "face.speakStream({ sampleRate: 24000, media: new MediaStream() });",
      // The microphone: the system's, or one of those listed.
      "import { listMicrophones, type Microphone } from 'talking-face';",
      "void listMicrophones().then((inputs: Microphone[]) => face.startMicrophone({ deviceId: inputs[0]?.deviceId }));",
      "void face.startMicrophone();",
      "// @ts-expect-error: an id is a string",
      "void face.startMicrophone({ deviceId: 3 });",
      // Loudness, as a media element's.
      "face.volume = 0.5; face.muted = !face.muted; const loud: number = face.volume; void loud;",
      "// @ts-expect-error: a volume is a number",
      "face.volume = 'loud';",
    ].join('\n'));
    writeFileSync(join(dir, 'tsconfig.json'), JSON.stringify({ compilerOptions: {
      target: 'ES2022', module: 'ESNext', moduleResolution: 'bundler', strict: true, skipLibCheck: false, noEmit: true,
      lib: ['ES2022', 'DOM', 'DOM.Iterable'], types: [] }, files: ['main.ts'] }));
    let out = '';
    try {
      execFileSync(process.execPath, [TSC, '-p', dir], { cwd: dir, encoding: 'utf8' });
    } catch (e) {
      out = String((e as { stdout?: string }).stdout ?? e);
    } finally {
      rmSync(dir, { recursive: true, force: true }); // (its links into node_modules are removed, not what they point at)
    }
    expect(out).toBe('');
  }, 120_000);
});
