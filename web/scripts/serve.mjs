// Serves web/ on localhost for the example page: node scripts/serve.mjs, then open the printed URL.
import { dirname, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import { serve } from '../test/serve.mjs';

const server = await serve(resolve(dirname(fileURLToPath(import.meta.url)), '..'));
console.log(`${server.url}/examples/index.html (Ctrl-C stops)`);
