// Programs of the examples as GET /api/programs/{name} returned them
// (text and rungs JSON), captured from `alba run`.
import type { RungJson } from '../src/types';
import startStop from './fixtures/start-stop-main.json';
import tank from './fixtures/tank-main.json';
import starDelta from './fixtures/star-delta-main.json';
import traffic from './fixtures/traffic-light-main.json';
import festo from './fixtures/festo-station-plant.json';
import nested from './fixtures/golden-bit-branch-nested.json';
import cpt from './fixtures/golden-math-cpt-functions.json';
import timerLegs from './fixtures/golden-timer-in-branch-legs.json';
import jmp from './fixtures/golden-flow-jmp-lbl.json';

export interface Fixture {
  example: string;
  name: string;
  text: string;
  rungs: RungJson[];
}

export const FIXTURES = [startStop, tank, starDelta, traffic, festo, nested, cpt, timerLegs, jmp] as Fixture[];
