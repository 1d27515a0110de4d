// Starts `flourish serve` on a free loopback port for the browser and
// load tests, and resolves with the process and the address it prints.
import { spawn } from 'node:child_process';

export function startServer(bin) {
  const server = spawn(bin, ['serve', '--port', '0'], { stdio: ['ignore', 'pipe', 'inherit'] });
  const url = new Promise((ok, fail) => {
    let text = '';
    server.stdout.on('data', (b) => {
      text += b;
      const m = /(http:\/\/\S+\/)/.exec(text);
      if (m) ok(m[1]);
    });
    server.on('exit', (code) => fail(new Error(`flourish serve exited with ${code}`)));
  });
  return { server, url };
}
