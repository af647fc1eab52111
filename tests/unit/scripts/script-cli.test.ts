/**
 * The measuring scripts' command line (scripts/script-cli.ts) and what bench and compare do with a wrong one: --help
 * and a bad option end before any work, with exit codes 0 and 2, and nothing is written; a port in use is seen.
 */
import { describe, expect, it } from 'vitest';
import { spawnSync } from 'node:child_process';
import { mkdtempSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { createServer } from 'node:net';
import { tmpdir } from 'node:os';
import { join, resolve } from 'node:path';
import { positiveNumbers, portFree, startServer, within } from '../../../scripts/script-cli';

const ROOT = resolve(import.meta.dirname, '../../..');
const run = (script: string, ...args: string[]) =>
  spawnSync('npx', ['tsx', `scripts/${script}.ts`, ...args], { cwd: ROOT, encoding: 'utf8', timeout: 60_000 });

describe('script-cli', () => {
  it('reads lists of positive numbers, and nothing else', () => {
    expect(positiveNumbers('10,60')).toEqual([10, 60]);
    expect(positiveNumbers('2.5')).toEqual([2.5]);
    for (const bad of ['abc', '10,', '0', '-1', '10,x', '']) expect(positiveNumbers(bad), bad).toBeNull();
  });

  it('gives up on work that never finishes, saying what; passes on what does', async () => {
    await expect(within(new Promise(() => undefined), 0.05, 'the benchmark page')).rejects.toThrow('the benchmark page did not finish within 0.05 s');
    await expect(within(Promise.resolve(7), 0.05, 'x')).resolves.toBe(7);
    await expect(within(Promise.reject(new Error('its own')), 5, 'x')).rejects.toThrow('its own');
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

  it('a script that fails outside its try (a browser that would not start) leaves no server behind', async () => {
    const dir = mkdtempSync(join(tmpdir(), 'script-cli-'));
    try {
      const pidFile = join(dir, 'server.pid');
      const server = `require("fs").writeFileSync(${JSON.stringify(pidFile)}, String(process.pid)); setInterval(() => {}, 1000)`;
      const script = `import { startServer } from ${JSON.stringify(resolve(ROOT, 'scripts/script-cli.ts'))};
        startServer('node', ['-e', ${JSON.stringify(server)}], '.');
        setTimeout(() => { throw new Error('chromium would not start'); }, 1500);`;
      writeFileSync(join(dir, 'fails.ts'), script);
      const r = spawnSync('npx', ['tsx', join(dir, 'fails.ts')], { cwd: ROOT, encoding: 'utf8', timeout: 60_000 });
      expect(r.status).not.toBe(0);
      const pid = Number(readFileSync(pidFile, 'utf8'));
      // Running: it answers signal 0 and is no zombie (killed, it waits a moment for its new parent to reap it).
      const running = () => {
        try {
          process.kill(pid, 0);
        } catch {
          return false;
        }
        return !/^\d+ \(.*\) Z/.test(readFileSync(`/proc/${pid}/stat`, 'utf8'));
      };
      const alive = running();
      if (alive) process.kill(pid); // (not left running after a failure of this test)
      expect(alive, `server ${pid} still running`).toBe(false);
    } finally {
      rmSync(dir, { recursive: true, force: true });
    }
  });

  it('bench, compare and avatar-fit: --help prints the usage; a wrong option, value or number stops them with exit 2', () => {
    for (const script of ['bench', 'compare', 'avatar-fit']) {
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
      ['avatar-fit', ['--max-clips', 'x'], /--max-clips x: a whole number from 1/],
      ['avatar-fit', ['--max-clip', '3'], /Unknown option '--max-clip'/],
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
