// Bundles the viewer for the Python package: the page script (IIFE) and the anywidget module
// (ESM), each with the CSS it imports, into src/collidium/viewer/static/ (build outputs, not
// committed). Run with `npm run build`; exits non-zero when esbuild reports an error.
import path from "node:path";
import { fileURLToPath } from "node:url";
import * as esbuild from "esbuild";

const here = path.dirname(fileURLToPath(import.meta.url));
const outdir = path.resolve(here, "../src/collidium/viewer/static");

const shared = {
  bundle: true,
  minify: true,
  sourcemap: false,
  target: "es2020",
  outdir,
  logLevel: "info",
};

const bundles = [
  { entryPoints: { app: path.join(here, "src/app.js") }, format: "iife" },
  { entryPoints: { widget: path.join(here, "src/widget.js") }, format: "esm" },
];

try {
  await Promise.all(bundles.map((bundle) => esbuild.build({ ...shared, ...bundle })));
} catch {
  // esbuild has already printed the errors (logLevel "info").
  process.exitCode = 1;
}
