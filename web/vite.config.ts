/// <reference types="vitest/config" />
import { defineConfig } from 'vite';

// The Rust server embeds dist/ and serves it at `/`: relative asset paths.
// In development `npm run dev` proxies the API (and its WebSocket) to a
// running `alba run … --http 127.0.0.1:8080`.
export default defineConfig({
  base: './',
  build: { outDir: 'dist', emptyOutDir: true, chunkSizeWarningLimit: 600 },
  server: {
    proxy: {
      '/api': { target: 'http://127.0.0.1:8080', ws: true, changeOrigin: true },
    },
  },
  test: {
    environment: 'happy-dom',
    include: ['test/**/*.test.ts'],
    setupFiles: ['test/setup.ts'],
  },
});
