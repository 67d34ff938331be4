// A static file server on localhost for the browser tests: ES modules need http(s), not file://.
// Serves `root` at / and each of `mounts` ({ '/prefix/': directory }) under its prefix.
import { createServer } from 'node:http';
import { readFile } from 'node:fs/promises';
import { extname, join, normalize, sep } from 'node:path';

const TYPES = {
  '.html': 'text/html; charset=utf-8',
  '.js': 'text/javascript; charset=utf-8',
  '.mjs': 'text/javascript; charset=utf-8',
  '.json': 'application/json',
  '.bin': 'application/octet-stream',
  '.png': 'image/png',
  '.css': 'text/css',
};

function inside(dir, rel) {
  const path = normalize(join(dir, rel));
  return path === dir || path.startsWith(dir.endsWith(sep) ? dir : dir + sep) ? path : null;
}

export async function serve(root, mounts = {}) {
  const server = createServer(async (req, res) => {
    const url = decodeURIComponent(new URL(req.url, 'http://localhost').pathname);
    let path = null;
    for (const [prefix, dir] of Object.entries(mounts))
      if (url.startsWith(prefix)) path = inside(dir, url.slice(prefix.length));
    if (path === null) path = inside(root, url);
    try {
      if (path === null) throw new Error('outside the served directories');
      const body = await readFile(path);
      res.writeHead(200, { 'Content-Type': TYPES[extname(path)] ?? 'application/octet-stream' });
      res.end(body);
    } catch {
      res.writeHead(404);
      res.end();
    }
  });
  await new Promise((resolve) => server.listen(0, '127.0.0.1', resolve));
  return { url: `http://127.0.0.1:${server.address().port}`, close: () => new Promise((r) => server.close(r)) };
}
