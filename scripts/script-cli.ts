/**
 * What the project's measuring scripts (bench, compare) share on the command line and around their servers: options
 * read strictly (an unknown option, a missing value or a bad number is an error with the usage, before any work and
 * before any result is written), --help, a port checked free before anything is built, and a server waited for
 * that says why it did not start.
 */
import { parseArgs } from 'node:util';
import { createServer } from 'node:net';
import { spawn } from 'node:child_process';

export type Options = Record<string, { type: 'string' | 'boolean'; default?: string | boolean }>;
export type Values = Record<string, string | boolean | undefined>;

/** The options given, or exit: 0 after printing `usage` for --help, 2 with what is wrong and the usage. */
export function readOptions(script: string, usage: string, options: Options, argv = process.argv.slice(2)): Values {
  try {
    const { values } = parseArgs({ args: argv, options: { ...options, help: { type: 'boolean', short: 'h' } }, strict: true, allowPositionals: false });
    if (values.help) {
      console.log(usage);
      process.exit(0);
    }
    return values as Values;
  } catch (e) {
    return usageError(script, usage, (e as Error).message);
  }
}

/** Exit 2 saying what is wrong with the command line, and how to use it. */
export function usageError(script: string, usage: string, message: string): never {
  console.error(`${script}: ${message}\n\n${usage}`);
  process.exit(2);
}

/** `work`, or an Error saying `what` did not finish within `seconds` (a page whose promise never settles would hold
 * the script, and its server, for ever). */
export async function within<T>(work: Promise<T>, seconds: number, what: string): Promise<T> {
  let timer: ReturnType<typeof setTimeout> | undefined;
  const late = new Promise<never>((_, reject) => {
    timer = setTimeout(() => reject(new Error(`${what} did not finish within ${seconds} s`)), seconds * 1000);
  });
  try {
    return await Promise.race([work, late]);
  } finally {
    clearTimeout(timer);
  }
}

/** A comma-separated list of numbers above zero ("10,60"), or null saying nothing valid was given. */
export function positiveNumbers(text: string): number[] | null {
  const xs = text.split(',').map((s) => Number(s.trim()));
  return xs.length > 0 && xs.every((x) => Number.isFinite(x) && x > 0) ? xs : null;
}

/** The port in environment variable `name` (default `fallback`), or exit 2 saying it is not one. */
export function envPort(script: string, usage: string, name: string, fallback: number): number {
  const port = Number(process.env[name] ?? fallback);
  return Number.isInteger(port) && port > 0 && port < 65536 ? port : usageError(script, usage, `${name} must be a port number (not ${process.env[name]})`);
}

/** Whether nothing listens on `port` of 127.0.0.1 (a server there would be measured instead of ours). */
export function portFree(port: number): Promise<boolean> {
  return new Promise((resolve) => {
    const probe = createServer();
    probe.once('error', () => resolve(false));
    probe.listen(port, '127.0.0.1', () => probe.close(() => resolve(true)));
  });
}

/** A server started for a script: its output and exit are followed from the start (a quick exit is not missed). */
export interface Server {
  /** Resolve once `url` answers 200; reject saying why if the server has exited (its last output) or does not answer within `seconds`. */
  ready(url: string, seconds?: number): Promise<void>;
  /** Stop it and whatever it started. */
  stop(): void;
}

/** The servers started and not yet stopped: each in its own process group (detached), which Ctrl-C does not reach. */
const running = new Set<() => void>();
let signalsHeld = false;

/** Ctrl-C (or a SIGTERM) stops every server still running, then the script: its `finally` would not run, and a server
 * left behind would hold its port for the next run. So does the script's exit on any other path (an error thrown
 * before its `try`, a browser that would not start). */
function stopOnSignals(): void {
  if (signalsHeld) return;
  signalsHeld = true;
  process.once('exit', () => {
    for (const stop of [...running]) stop();
  });
  for (const signal of ['SIGINT', 'SIGTERM'] as const) {
    process.once(signal, () => {
      for (const stop of [...running]) stop();
      process.exit(128 + (signal === 'SIGINT' ? 2 : 15));
    });
  }
}

export function startServer(command: string, args: string[], cwd: string): Server {
  const child = spawn(command, args, { cwd, stdio: ['ignore', 'pipe', 'pipe'], detached: true });
  let output = '';
  const keep = (d: Buffer) => (output = (output + d.toString()).slice(-2000));
  child.stdout.on('data', keep);
  child.stderr.on('data', keep);
  const exited = () => child.exitCode ?? child.signalCode;
  const stop = (): void => {
    running.delete(stop);
    try {
      process.kill(-child.pid!);
    } catch {
      /* already gone */
    }
  };
  running.add(stop);
  stopOnSignals();
  return {
    async ready(url: string, seconds = 60): Promise<void> {
      const deadline = Date.now() + seconds * 1000;
      for (let last = ''; ; await new Promise((r) => setTimeout(r, 250))) {
        if (exited() !== null) throw new Error(`the server for ${url} exited (${exited()}) before it answered:\n${output.trim()}`);
        try {
          const res = await fetch(url);
          if (res.ok) return;
          last = `HTTP ${res.status}`;
        } catch (e) {
          last = (e as Error).message;
        }
        if (Date.now() > deadline) throw new Error(`${url} did not answer within ${seconds} s (last: ${last})${output ? `:\n${output.trim()}` : ''}`);
      }
    },
    stop,
  };
}
