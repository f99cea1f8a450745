// The top bar's commands — Run, Stop, Compile, Save — enabled for what can be
// done now: the role allows it (auth.ts), the runtime answers (not "Not live":
// a click would only raise error toasts), Run while not running and Stop while
// running, Compile and Save on a program tab. A disabled one says why in its
// tooltip; an enabled one keeps its own.
import { why } from '../auth';
import { tr } from '../i18n';

export interface CommandButtons {
  run: HTMLButtonElement;
  stop: HTMLButtonElement;
  compile: HTMLButtonElement;
  save: HTMLButtonElement;
}

export interface CommandState {
  /** The runtime does not answer (live/freshness.ts `stale`). */
  stale: boolean;
  /** The runtime's state (`running`, `stopped`, `faulted`). */
  state: string;
  /** The tab shown is a program's (Compile and Save act on it). */
  editor: boolean;
}

export const commandText = {
  notLive: tr('Not live: the runtime does not answer'),
  noProgram: tr('Open a program tab first'),
};

function show(b: HTMLButtonElement, reason: string | undefined | null, off = false): void {
  b.dataset.title ??= b.title;
  b.disabled = !!reason || off;
  b.title = reason ?? b.dataset.title;
}

export function showCommands(b: CommandButtons, s: CommandState): void {
  const stale = s.stale ? commandText.notLive : null;
  show(b.run, why('runstop') ?? stale, s.state === 'running');
  show(b.stop, why('runstop') ?? stale, s.state !== 'running');
  const program = s.editor ? null : commandText.noProgram;
  show(b.compile, why('edit') ?? program ?? stale);
  show(b.save, why('edit') ?? program ?? stale);
}
