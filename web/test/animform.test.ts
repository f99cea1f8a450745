// The designer's animation forms and previews (issue 35, points 2 and 3):
// the fields come from the domain's parameter table, each sets or removes
// its parameter, and the previews draw where a move ends and the path of a
// rotation about its anchor.
import { describe, expect, it } from 'vitest';
import { animationForm, animationPreview, paramsOf } from '../src/hmi/animform';
import type { Animation, Element } from '../src/hmi/render';
import type { Json } from '../src/types';

function form(a: Animation) {
  const sets: [string, Json | undefined][] = [];
  const f = animationForm(a, 'f', (name, v) => sets.push([name, v]));
  document.body.replaceChildren(f);
  const q = <T extends HTMLElement>(id: string) => f.querySelector<T>(`[data-testid="f-${id}"]`);
  const change = (id: string, value: string) => {
    const input = q<HTMLInputElement | HTMLSelectElement>(id)!;
    input.value = value;
    input.dispatchEvent(new Event('change'));
  };
  return { f, q, sets, change };
}

describe('animation forms', () => {
  it('come from the domain: every kind has its typed parameters', () => {
    expect(paramsOf('blink').map((p) => [p.name, p.kind, p.unit])).toEqual([
      ['when', 'bool', ''], ['min', 'number', ''], ['max', 'number', ''], ['on_ms', 'number', 'ms'], ['off_ms', 'number', 'ms'], ['period_ms', 'number', 'ms'],
    ]);
    expect(paramsOf('fill').find((p) => p.name === 'direction')!.choices).toEqual(['up', 'down', 'left', 'right']);
    expect(paramsOf('rotate').map((p) => p.name)).toEqual(['min', 'max', 'from', 'degrees', 'speed', 'cx', 'cy', 'when']);
  });

  it('set a number with its unit and range, and remove it when emptied', () => {
    const { q, sets, change } = form({ kind: 'blink', tag: 'B', on_ms: 300 });
    const on = q<HTMLInputElement>('on_ms')!;
    expect([on.type, on.value, on.min, on.max]).toEqual(['number', '300', '10', '600000']);
    expect(on.closest('label')!.textContent).toContain('on_ms (ms)');
    // the older period_ms only when the file has it
    expect(q('period_ms')).toBeNull();
    change('off_ms', '700');
    change('on_ms', '');
    change('when', 'false');
    change('when', '');
    expect(sets).toEqual([['off_ms', 700], ['on_ms', undefined], ['when', false], ['when', undefined]]);
    expect(form({ kind: 'blink', tag: 'B', period_ms: 400 }).q<HTMLInputElement>('period_ms')!.value).toBe('400');
  });

  it('choose a colour, a choice and up to four intervals', () => {
    const { q, sets, change } = form({ kind: 'color', tag: 'L', on: 'green', intervals: [{ from: 0, color: '#9ea3a8' }] });
    expect(q<HTMLInputElement>('on')!.value).toBe('green');
    change('on-swatch', '#c62828');
    change('off', ' ');
    change('intervals-0-from', '5');
    q<HTMLButtonElement>('intervals-add')!.click();
    q<HTMLButtonElement>('intervals-0-remove')!.click();
    expect(sets).toEqual([
      ['on', '#c62828'],
      ['off', undefined],
      ['intervals', [{ from: 5, color: '#9ea3a8' }]],
      ['intervals', [{ from: 0, color: '#9ea3a8' }, { from: 10, color: '#9ea3a8' }]],
      ['intervals', undefined],
    ]);
    const full = form({ kind: 'color', tag: 'L', intervals: [0, 1, 2, 3].map((from) => ({ from, color: '#000000' })) });
    expect(full.q<HTMLButtonElement>('intervals-add')!.disabled).toBe(true);
    const fill = form({ kind: 'fill', tag: 'L' });
    fill.change('direction', 'left');
    expect(fill.sets).toEqual([['direction', 'left']]);
  });
});

describe('move and rotate previews', () => {
  const el = (animations: Animation[]): Element => ({ id: 'e', type: 'rectangle', x: 10, y: 20, w: 40, h: 20, animations });
  const part = (g: SVGGElement | null, p: string) => g?.querySelector(`[data-part="${p}"]`) ?? null;

  it('draws where a move ends', () => {
    const g = animationPreview(el([{ kind: 'move', tag: 'X', dx: 100, dy: -30 }]), true);
    expect(['x', 'y', 'width', 'height'].map((k) => part(g, 'move-ghost')!.getAttribute(k))).toEqual(['100', '-30', '40', '20']);
    expect(['x1', 'y1', 'x2', 'y2'].map((k) => part(g, 'move-path')!.getAttribute(k))).toEqual(['20', '10', '120', '-20']);
    expect(animationPreview(el([{ kind: 'move', tag: 'X' }]), true)).toBeNull();
  });

  it('draws the arc a rotation follows about its anchor, and a spin as a circle', () => {
    // the centre (20, 10) about the anchor (0, 10): from -90° (straight up) to 90° (straight down), clockwise
    const g = animationPreview(el([{ kind: 'rotate', tag: 'X', from: -90, degrees: 90, cx: 0, cy: 10 }]), false);
    expect(part(g, 'rotate-path')!.getAttribute('d')).toBe('M 0 -10 A 20 20 0 0 1 0 30');
    expect(part(g, 'rotate-ghost')!.getAttribute('transform')).toBe('rotate(90 0 10)');
    expect(part(g, 'anchor')).not.toBeNull();
    const spin = animationPreview(el([{ kind: 'rotate', tag: 'B', speed: 1, cx: 0, cy: 10 }]), true);
    expect([part(spin, 'rotate-path')!.tagName, part(spin, 'rotate-path')!.getAttribute('r'), part(spin, 'rotate-ghost')]).toEqual(['circle', '20', null]);
    // a pump's rotor turns inside it: nothing to preview without an anchor
    expect(animationPreview(el([{ kind: 'rotate', tag: 'B', speed: 1 }]), false)).toBeNull();
  });
});
