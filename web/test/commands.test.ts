// The top bar's Run/Stop/Compile/Save (issue 30, item 22): disabled while the
// runtime does not answer, instead of raising error toasts, each saying why.
import { describe, expect, it } from 'vitest';
import { setMe } from '../src/auth';
import { h } from '../src/dom';
import { showCommands } from '../src/ui/commands';

function buttons() {
  return {
    run: h('button', { title: 'Start scanning' }),
    stop: h('button', { title: 'Stop scanning (outputs off)' }),
    compile: h('button', { title: 'Check the program being edited' }),
    save: h('button', { title: 'Save the program and apply it online' }),
  };
}
const state = (b: ReturnType<typeof buttons>) => Object.fromEntries(Object.entries(b).map(([k, el]) => [k, el.disabled ? `off: ${el.title}` : 'on']));

describe('Run, Stop, Compile and Save', () => {
  it('follow the run state and the tab, and are all disabled while not live', () => {
    const b = buttons();
    showCommands(b, { stale: false, state: 'running', editor: true });
    expect(state(b)).toEqual({ run: 'off: Start scanning', stop: 'on', compile: 'on', save: 'on' });
    expect(b.stop.title).toBe('Stop scanning (outputs off)');
    showCommands(b, { stale: true, state: 'running', editor: true });
    const why = 'off: Not live: the runtime does not answer';
    expect(state(b)).toEqual({ run: why, stop: why, compile: why, save: why });
    showCommands(b, { stale: false, state: 'stopped', editor: false });
    expect(state(b)).toEqual({ run: 'on', stop: 'off: Stop scanning (outputs off)', compile: 'off: Open a program tab first', save: 'off: Open a program tab first' });
    expect(b.run.title).toBe('Start scanning');
  });

  it('say the role first', () => {
    setMe({ user: 'ann', role: 'operator', users: true });
    const b = buttons();
    showCommands(b, { stale: true, state: 'stopped', editor: true });
    expect(state(b)).toEqual({
      run: 'off: needs the engineer role',
      stop: 'off: needs the engineer role',
      compile: 'off: needs the engineer role',
      save: 'off: needs the engineer role',
    });
  });
});
