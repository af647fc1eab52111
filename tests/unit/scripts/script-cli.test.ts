/**
 * The measuring scripts' command line (scripts/script-cli.ts) and what bench and compare do with a wrong one: --help
 * and a bad option end before any work, with exit codes 0 and 2, and nothing is written; a port in use is seen.
 */
import { describe, expect, it } from 'vitest';
import { spawnSync } from 'node:child_process';
import { createServer } from 'node:net';
import { resolve } from 'node:path';
import { positiveNumbers, portFree, startServer } from '../../../scripts/script-cli';

const ROOT = resolve(import.meta.dirname, '../../..');
const run = (script: string, ...args: string[]) =>
  spawnSync('npx', ['tsx', `scripts/${script}.ts`, ...args], { cwd: ROOT, encoding: 'utf8', timeout: 60_000 });

describe('script-cli', () => {
  it('reads lists of positive numbers, and nothing else', () => {
    expect(positiveNumbers('10,60')).toEqual([10, 60]);
    expect(positiveNumbers('2.5')).toEqual([2.5]);
    for (const bad of ['abc', '10,', '0', '-1', '10,x', '']) expect(positiveNumbers(bad), bad).toBeNull();
  });

  it('sees a port in use', async () => {
    const server = createServer();
    await new Promise<void>((r) => server.listen(0, '127.0.0.1', r));
    const port = (server.address() as { port: number }).port;
    expect(await portFree(port)).toBe(false);
    await new Promise((r) => server.close(r));
    expect(await portFree(port)).toBe(true);
  });

  it('says why a server did not start: it exited, with its output, even when it exited before it was waited for', async () => {
    const server = startServer('node', ['-e', 'console.error("Port 1 is already in use"); process.exit(1)'], ROOT);
    await new Promise((r) => setTimeout(r, 1500)); // gone by now, its output read
    await expect(server.ready('http://127.0.0.1:9/', 20)).rejects.toThrow(/exited \(1\)[\s\S]*already in use/);
  });

  it('bench and compare: --help prints the usage; a wrong option, value or number stops them with exit 2', () => {
    for (const script of ['bench', 'compare']) {
      const help = run(script, '--help');
      expect(help.status, `${script} --help`).toBe(0);
      expect(help.stdout).toContain(`npm run ${script}`);
    }
    for (const [script, args, says] of [
      ['bench', ['--seconds', 'abc'], /--seconds takes clip lengths above 0/],
      ['bench', ['--backends', 'gpu'], /--backends takes cpu and\/or webgpu/],
      ['bench', ['--seconds'], /argument missing/],
      ['bench', ['--first-load-url', 'http://x/'], /goes with --first-load-only/],
      ['compare', ['--max-clips', '0'], /--max-clips takes a whole number above 0/],
      ['compare', ['--max-clip', '3'], /Unknown option '--max-clip'/],
      ['compare', ['--corpus', '/nonexistent'], /no corpus there/],
      ['compare', ['--samples', 'models/samples'], /--samples needs --out/],
    ] as const) {
      const r = run(script, ...args);
      expect(r.status, `${script} ${args.join(' ')}`).toBe(2);
      expect(r.stderr).toMatch(says);
    }
  }, 120_000);

  it('npm run demo on a port in use stops before it builds (the demo on it keeps its files)', async () => {
    const server = createServer();
    await new Promise<void>((r) => server.listen(0, 'localhost', r));
    const port = (server.address() as { port: number }).port;
    const r = spawnSync('bash', ['scripts/demo.sh'], { cwd: ROOT, encoding: 'utf8', timeout: 20_000, env: { ...process.env, PORT: String(port) } });
    await new Promise((done) => server.close(done));
    expect(r.status).toBe(1);
    expect(r.stderr).toContain(`port ${port} is in use`);
    expect(r.stdout + r.stderr).not.toContain('building');
  });
});
