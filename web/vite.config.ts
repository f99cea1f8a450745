/// <reference types="vitest/config" />
import { readFileSync, readdirSync, statSync, writeFileSync } from 'node:fs';
import { join } from 'node:path';
import { brotliCompressSync, constants, gzipSync } from 'node:zlib';
import { type Plugin, defineConfig } from 'vite';

/**
 * Writes `file.gz` and `file.br` beside every text asset of the build, so the
 * server sends them as they are to a browser that accepts them (crates/server
 * /src/assets.rs): the best compression, paid once at build time.
 */
function precompress(): Plugin {
  const text = /\.(js|mjs|css|html|svg|json|txt)$/;
  let outDir = 'dist';
  const files = (dir: string): string[] =>
    readdirSync(dir).flatMap((f) => (statSync(join(dir, f)).isDirectory() ? files(join(dir, f)) : [join(dir, f)]));
  return {
    name: 'alba-precompress',
    apply: 'build',
    configResolved: (c) => void (outDir = c.build.outDir),
    closeBundle() {
      for (const f of files(outDir).filter((f) => text.test(f))) {
        const raw = readFileSync(f);
        writeFileSync(`${f}.gz`, gzipSync(raw, { level: 9 }));
        writeFileSync(
          `${f}.br`,
          brotliCompressSync(raw, {
            params: { [constants.BROTLI_PARAM_QUALITY]: 11, [constants.BROTLI_PARAM_SIZE_HINT]: raw.length },
          }),
        );
      }
    },
  };
}

// The Rust server embeds dist/ and serves it at `/`: relative asset paths.
// In development `npm run dev` proxies the API (and its WebSocket) to a
// running `alba run … --http 127.0.0.1:8080`. The server refuses a foreign
// `Origin` (a page of another site acting on it), so the proxy presents its
// requests as the server's own page.
export default defineConfig({
  base: './',
  plugins: [precompress()],
  build: { outDir: 'dist', emptyOutDir: true, chunkSizeWarningLimit: 600 },
  server: {
    proxy: {
      '/api': {
        target: 'http://127.0.0.1:8080',
        ws: true,
        changeOrigin: true,
        configure: (proxy) => {
          const own = (req: { getHeader(n: string): unknown; setHeader(n: string, v: string): void }) => {
            if (req.getHeader('origin')) req.setHeader('origin', 'http://127.0.0.1:8080');
          };
          proxy.on('proxyReq', own);
          proxy.on('proxyReqWs', own);
        },
      },
    },
  },
  test: {
    environment: 'happy-dom',
    include: ['test/**/*.test.ts'],
    setupFiles: ['test/setup.ts'],
  },
});
