/**
 * Mesh connectivity: the 1-ring adjacency that masks GAVA's attention
 * (each vertex attends to its mesh neighbours and itself, paper Sec. III-D),
 * and the boundary loops that tell an opened mouth from a closed one.
 */

/** Compressed sparse rows: neighbours of v are indices[offsets[v] .. offsets[v+1]), ascending. */
export interface Adjacency {
  offsets: Uint32Array;
  indices: Uint32Array;
}

/** 1-ring neighbours from triangle edges: symmetric, no self loops, sorted per vertex. */
export function buildAdjacency(vertexCount: number, triangles: Uint32Array): Adjacency {
  const sets: Set<number>[] = Array.from({ length: vertexCount }, () => new Set<number>());
  for (let t = 0; t < triangles.length; t += 3) {
    for (let k = 0; k < 3; k++) {
      const a = triangles[t + k];
      const b = triangles[t + ((k + 1) % 3)];
      if (a === b) continue;
      sets[a].add(b);
      sets[b].add(a);
    }
  }
  const offsets = new Uint32Array(vertexCount + 1);
  for (let v = 0; v < vertexCount; v++) offsets[v + 1] = offsets[v] + sets[v].size;
  const indices = new Uint32Array(offsets[vertexCount]);
  for (let v = 0; v < vertexCount; v++) {
    indices.set([...sets[v]].sort((x, y) => x - y), offsets[v]);
  }
  return { offsets, indices };
}

export function neighbours(adj: Adjacency, v: number): Uint32Array {
  return adj.indices.subarray(adj.offsets[v], adj.offsets[v + 1]);
}

/**
 * Closed loops of boundary edges (edges used by exactly one triangle), each as
 * an ordered vertex list. An opened face has four: the outer oval, the mouth
 * and the two eyes.
 */
export function boundaryLoops(triangles: Uint32Array): number[][] {
  const count = new Map<string, number>();
  const directed: [number, number][] = [];
  for (let t = 0; t < triangles.length; t += 3) {
    for (let k = 0; k < 3; k++) {
      const a = triangles[t + k];
      const b = triangles[t + ((k + 1) % 3)];
      const key = a < b ? `${a},${b}` : `${b},${a}`;
      count.set(key, (count.get(key) ?? 0) + 1);
      directed.push([a, b]);
    }
  }
  const next = new Map<number, number>();
  for (const [a, b] of directed) {
    if (count.get(a < b ? `${a},${b}` : `${b},${a}`) === 1) {
      if (next.has(a)) throw new Error(`vertex ${a} has two outgoing boundary edges: the mesh is not a manifold with boundary`);
      next.set(a, b);
    }
  }
  const loops: number[][] = [];
  const seen = new Set<number>();
  for (const start of next.keys()) {
    if (seen.has(start)) continue;
    const loop: number[] = [];
    let v = start;
    while (!seen.has(v)) {
      seen.add(v);
      loop.push(v);
      const n = next.get(v);
      if (n === undefined) throw new Error(`boundary is not closed at vertex ${v}`);
      v = n;
    }
    loops.push(loop);
  }
  return loops;
}

/** Split an undirected edge list into its connected chains/cycles, each as an ordered vertex list (a chain from one end). */
export function edgeCycles(edges: ReadonlyArray<readonly [number, number]>): number[][] {
  const nbr = new Map<number, number[]>();
  for (const [a, b] of edges) {
    (nbr.get(a) ?? nbr.set(a, []).get(a)!).push(b);
    (nbr.get(b) ?? nbr.set(b, []).get(b)!).push(a);
  }
  const seen = new Set<number>();
  const cycles: number[][] = [];
  const ends = [...nbr.keys()].filter((v) => nbr.get(v)!.length === 1); // a chain walked from the middle would split in two
  for (const start of [...ends, ...nbr.keys()]) {
    if (seen.has(start)) continue;
    const cycle = [start];
    seen.add(start);
    let prev = -1;
    let cur = start;
    for (;;) {
      const nxt = nbr.get(cur)!.find((x) => x !== prev && !seen.has(x));
      if (nxt === undefined) break;
      cycle.push(nxt);
      seen.add(nxt);
      prev = cur;
      cur = nxt;
    }
    cycles.push(cycle);
  }
  return cycles;
}
