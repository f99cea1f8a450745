/// <reference types="vitest/config" />
import { defineConfig } from 'vite';

// The Rust server embeds dist/ and serves it at `/`: relative asset paths.
// In development `npm run dev` proxies the API (and its WebSocket) to a
// running `alba run … --http 127.0.0.1:8080`. The server refuses a foreign
// `Origin` (a page of another site acting on it), so the proxy presents its
// requests as the server's own page.
export default defineConfig({
  base: './',
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
