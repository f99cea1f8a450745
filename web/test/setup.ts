// Every unit test runs with the domain the server serves (GET /api/domain),
// from a copy of its reply that the server's tests keep equal to it
// (crates/server/tests/it/domain.rs; ALBA_BLESS=1 rewrites it), and with the
// rights of a project without users (full rights, as `alba demo`); the tests
// of roles set their user themselves (auth.test.ts, login.test.ts).
import { beforeEach } from 'vitest';
import { LOCAL, setMe } from '../src/auth';
import { type Domain, setDomain } from '../src/domain';
import domain from './fixtures/domain.json';

setDomain(domain as Domain);
beforeEach(() => setMe(LOCAL));
