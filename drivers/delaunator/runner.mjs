// Our runner of Delaunator for the harness (drivers/delaunator/__init__.py).
// node runner.mjs POINTS.bin OUT.bin
// POINTS.bin: n x 2 little-endian float64 (x0, y0, x1, y1, ...), the flat
// coordinate array Delaunator's constructor takes.  One untimed warm-up on
// the same points lets V8 optimise the code first, as the harness warms up
// every peer; then `new Delaunator(coords)` is timed with performance.now().
// OUT.bin: the triangles, 3 uint32 vertex ids each; stdout: one JSON line.
import { readFileSync, writeFileSync } from "node:fs";
import { createRequire } from "node:module";
import Delaunator from "delaunator";

const [pointsPath, outPath] = process.argv.slice(2);
const bytes = readFileSync(pointsPath);
const coords = new Float64Array(bytes.buffer, bytes.byteOffset, bytes.byteLength / 8);
new Delaunator(coords);
const baseline = process.memoryUsage().rss;
const t0 = performance.now();
const d = new Delaunator(coords);
const seconds = (performance.now() - t0) / 1000;
const peak = process.resourceUsage().maxRSS * 1024;
const tri = d.triangles;
writeFileSync(outPath, Buffer.from(tri.buffer, tri.byteOffset, tri.byteLength));
const version = createRequire(import.meta.url)("delaunator/package.json").version;
console.log(JSON.stringify({ seconds, tsc_cycles: null, triangles: tri.length / 3,
  peak_rss_bytes: peak, baseline_rss_bytes: baseline, version, node: process.version }));
