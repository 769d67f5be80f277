// Threads of the page's threaded bundle (web/pkg-threads, built with WebAssembly atomics): each
// is a module Web Worker that instantiates the page's module on the page's shared memory and runs
// one Rust thread (src/web_threads.rs). wasm-bindgen copies this file into the bundle's snippets;
// the workers load this same file, and from it the bundle's entry (three folders up).

/** Starts a worker running the Rust thread `entry` (a pointer the module made for it); resolves
 * once the module is instantiated there and the thread is about to run. */
export function spawnThread(module, memory, entry) {
  return new Promise((resolve, reject) => {
    const worker = new Worker(new URL('./threads.js', import.meta.url), { type: 'module', name: 'knotwork' });
    worker.onmessage = (event) => {
      if (event.data === 'ready') resolve();
      else if (event.data && event.data.error) reject(new Error(event.data.error));
    };
    worker.onerror = (event) => reject(new Error(`a worker thread failed to start: ${event.message}`));
    worker.postMessage({ module, memory, entry });
  });
}

if (typeof WorkerGlobalScope !== 'undefined' && globalThis instanceof WorkerGlobalScope) {
  globalThis.onmessage = async ({ data }) => {
    let bindings;
    try {
      bindings = await import('../../../knotwork.js');
      await bindings.default({ module_or_path: data.module, memory: data.memory });
    } catch (e) {
      postMessage({ error: `a worker thread could not instantiate the module: ${e}` });
      return;
    }
    postMessage('ready');
    bindings.knotworkThreadEntry(data.entry);
  };
}
