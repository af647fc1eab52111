import { defineConfig, defaultClientConditions } from 'vite';
import { cpSync } from 'node:fs';
import { resolve } from 'node:path';
import { precompress } from './scripts/hosting.ts';
import { vendorProjectThree, vendorTalkingHead, vendorThreeVrm } from './scripts/talkinghead-vendor.ts';
import { captureWorkletFile } from './scripts/worklet-file.ts';

/**
 * The library build: dist/lib/talking-face.js (ES module) defines <talking-face> and exports the API
 * (src/component/index.ts). It runs after the app build (npm run build), whose dist/models/ and
 * dist/ort/ it uses: deploy lib/, models/ and ort/ side by side (docs/embedding.md). The example pages
 * (examples/) are copied to dist/examples/, with TalkingHead and its three.js in dist/examples/vendor/ for
 * examples/talkinghead.html, and the project's own three.js in dist/examples/vendor/three-project/ for
 * examples/own-scene.html, with @pixiv/three-vrm in dist/examples/vendor/three-vrm/ for its .vrm avatars
 * (scripts/talkinghead-vendor.ts).
 *
 * `--mode npm` builds the same entry for bundlers into dist/lib/npm/ (the package's import): three.js is left to the
 * project that installs it (a peer dependency), so a page with its own three.js scene has one copy of it, not two.
 * dist/lib/talking-face.js keeps its own, for a page that loads it with one script tag and no bundler.
 * dist/lib/npm/engine.js (`talking-face/engine`) is the library without the element, for a page that draws its own.
 */
export default defineConfig(({ mode }) => mode === 'npm' ? forBundlers : standalone);

const standalone = defineConfig({
  // Relative: the library's workers (lib/assets/) are found beside talking-face.js wherever lib/ is deployed, not at
  // the site's root /assets/ (where only the demo's build put copies of them).
  base: './',
  publicDir: false,
  build: {
    outDir: 'dist/lib',
    emptyOutDir: true,
    target: 'es2022',
    sourcemap: true,
    chunkSizeWarningLimit: 1024,
    lib: {
      entry: resolve(import.meta.dirname, 'src/component/index.ts'),
      formats: ['es'],
      fileName: () => 'talking-face.js',
    },
  },
  plugins: [
    captureWorkletFile(),
    {
      name: 'talking-face-examples',
      closeBundle() {
        cpSync(resolve(import.meta.dirname, 'examples'), resolve(import.meta.dirname, 'dist/examples'), { recursive: true });
        vendorTalkingHead(resolve(import.meta.dirname, 'dist/examples/vendor'));
        vendorProjectThree(resolve(import.meta.dirname, 'dist/examples/vendor'), import.meta.dirname);
        vendorThreeVrm(resolve(import.meta.dirname, 'dist/examples/vendor'), import.meta.dirname);
        for (const dir of ['dist/lib', 'dist/examples']) precompress(resolve(import.meta.dirname, dir));
      },
    },
  ],
  resolve: { conditions: ['onnxruntime-web-use-extern-wasm', ...defaultClientConditions] },
});

const forBundlers = defineConfig({
  base: './',
  publicDir: false,
  build: {
    outDir: 'dist/lib/npm',
    emptyOutDir: true,
    // Not minified: the project's bundler minifies, and until then errors and devtools name the element's class and
    // its functions as the sources do (minified, <talking-face> was `$`).
    minify: false,
    target: 'es2022',
    sourcemap: true,
    chunkSizeWarningLimit: 1024,
    // Two entries: the element and the library (talking-face.js), and the library alone (engine.js: `talking-face/engine`,
    // which defines no element and does not bring the face's renderer); what they share goes in a chunk of its own.
    lib: {
      // jsx.js, vue.js, svelte.js: talking-face/jsx, /vue and /svelte hold only declarations; modules with nothing in
      // them, for an `import` that is not `import type`.
      entry: {
        'talking-face': resolve(import.meta.dirname, 'src/component/index.ts'),
        engine: resolve(import.meta.dirname, 'src/index.ts'),
        ...Object.fromEntries(['jsx', 'vue', 'svelte'].map((name) => [name, resolve(import.meta.dirname, `src/component/${name}.ts`)])),
      },
      formats: ['es'],
      fileName: (_format, name) => `${name}.js`,
    },
    rollupOptions: { external: [/^three($|\/)/] },
  },
  plugins: [captureWorkletFile()],
  resolve: standalone.resolve,
});
