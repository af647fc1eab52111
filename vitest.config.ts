import { defineConfig } from 'vitest/config';

export default defineConfig({
  test: {
    include: ['tests/unit/**/*.test.ts'],
    environment: 'node',
    testTimeout: 30_000,
    // Relaxed SIMD, as browsers have it: the SIMD kernel's fused matrix product (src/attention/simd-kernel.ts) runs here too.
    execArgv: ['--experimental-wasm-relaxed-simd'],
  },
});
