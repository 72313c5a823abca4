// Serves papertear's viewer for one run on this machine only (127.0.0.1):
//   node tools/viewer/serve.mjs RUN_DIR [--port N] [--modules DIR]
// then open the printed address. RUN_DIR is a run's output folder (with animation.glb);
// --modules is where npm put three.js (tools/clients/install.sh; default build/clients).
import { createServer } from 'node:http';
import { readFile, stat } from 'node:fs/promises';
import { dirname, extname, join, normalize, resolve, sep } from 'node:path';
import { fileURLToPath } from 'node:url';

const here = dirname(fileURLToPath(import.meta.url));
const types = { '.html': 'text/html', '.js': 'text/javascript', '.glb': 'model/gltf-binary', '.png': 'image/png',
                '.mp4': 'video/mp4', '.json': 'application/json' };

// The file under `root` that `rest` names, or null for a path that leaves it.
function inside(root, rest) {
  const path = normalize(join(root, decodeURIComponent(rest)));
  return path === root || path.startsWith(root + sep) ? path : null;
}

// Starts the server; resolves to it once it listens (port 0: any free port).
export function serve(runDir, { port = 8035, modules = join(here, '..', '..', 'build', 'clients', 'node_modules') } = {}) {
  const run = resolve(runDir), three = resolve(modules, 'three');
  const server = createServer(async (req, res) => {
    const url = new URL(req.url, 'http://localhost');
    const path = url.pathname === '/' ? join(here, 'viewer.html')
               : url.pathname.startsWith('/three/') ? inside(three, url.pathname.slice(7))
               : inside(run, url.pathname.slice(1));
    try {
      if (!path || !(await stat(path)).isFile()) throw new Error('not a file');
      res.writeHead(200, { 'content-type': types[extname(path)] ?? 'application/octet-stream' });
      res.end(await readFile(path));
    } catch {
      res.writeHead(404).end('not found');
    }
  });
  return new Promise((ok, fail) => {
    server.once('error', fail);
    server.listen(port, '127.0.0.1', () => ok(server));
  });
}

if (process.argv[1] === fileURLToPath(import.meta.url)) {
  const args = process.argv.slice(2);
  const option = (name) => { const i = args.indexOf(name); return i >= 0 ? args.splice(i, 2)[1] : undefined; };
  const port = Number(option('--port') ?? 8035), modules = option('--modules');
  if (args.length !== 1) {
    console.error('usage: node tools/viewer/serve.mjs RUN_DIR [--port N] [--modules DIR]');
    process.exit(2);
  }
  try {
    await stat(join(args[0], 'animation.glb'));
    await stat(join(modules ?? join(here, '..', '..', 'build', 'clients', 'node_modules'), 'three'));
  } catch (e) {
    console.error(`papertear viewer: ${e.path} is missing (run the scene, and tools/clients/install.sh)`);
    process.exit(1);
  }
  const server = await serve(args[0], { port, ...(modules ? { modules } : {}) });
  console.log(`papertear viewer: http://127.0.0.1:${server.address().port}/ (Ctrl-C stops it)`);
}
