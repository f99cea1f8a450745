//! Tests of `alba.toml` parsing, table by table.

use super::*;
use alba_diag::Files;
use alba_model::board::{Model, Pin, PinMap};
use alba_project::config::*;
use alba_settings::*;

/// The project's tables (`c`) and the services' (`s`).
#[derive(Debug)]
struct Parsed {
    c: Config,
    s: Settings,
}

fn parse(text: &str) -> Result<Parsed, Vec<String>> {
    let mut files = Files::new();
    let f = files.add("alba.toml", text);
    match parse_both(text, f) {
        (Some(c), Some(s), d) if d.is_empty() => Ok(Parsed { c, s }),
        (_, _, d) => Err(d.iter().map(|d| d.short(&files)).collect()),
    }
}

#[test]
fn names_with_quotes_and_backslashes_round_trip() {
    for name in ["plain", "a\\b", "say \"hi\"", "tab\there", "ñandú"] {
        let text = format!("name = {}\nprograms = [\"a.lad\"]\n", toml_string(name));
        assert_eq!(parse(&text).unwrap().c.name, name, "{text}");
    }
}

#[test]
fn minimal_config_takes_defaults() {
    let c = parse("name = \"tank\"\nprograms = [\"main.lad\"]\n").unwrap();
    assert_eq!(c.c.scan_ms, 10);
    assert_eq!(c.c.programs[0].0, "main.lad");
    assert!(c.c.board.is_none());
}

#[test]
fn retain_and_history_settings() {
    let c = parse("name = \"x\"\nprograms = [\"a.lad\"]\n").unwrap();
    assert_eq!((c.s.retain_ms, c.s.history.clone()), (1000, History::default()));
    let c = parse(
        "name = \"x\"\nretain_ms = 250\nprograms = [\"a.lad\"]\n[runtime]\non_retain_error = \"refuse\"\n\
         [history]\nretention_days = 0\nsample_ms = 500\ndeadband = 0.5\nmax_mb = 0\nmin_free_mb = 10\non_damage = \"refuse\"\n",
    )
    .unwrap();
    assert_eq!(c.s.retain_ms, 250);
    assert_eq!(c.s.runtime.on_retain_error, alba_settings::OnRetainError::Refuse);
    assert_eq!(
        c.s.history,
        History {
            enabled: true,
            retention_days: 0,
            sample_ms: 500,
            deadband: 0.5,
            max_mb: 0,
            min_free_mb: 10,
            on_damage: alba_settings::OnDamage::Refuse,
            ..History::default()
        }
    );
    let c = parse(
        "name = \"x\"\nprograms = [\"a.lad\"]\n[history]\nbackend = \"postgres\"\n\
         url = \"postgres://alba@db.plant:5432/history\"\npassword_file = \"/run/secrets/pg\"\n\
         node = \"line-2\"\nbuffer_max_samples = 1000\n",
    )
    .unwrap();
    assert_eq!(c.s.history.backend, alba_settings::HistoryBackend::Postgres);
    assert_eq!(
        c.s.history.url.as_deref(),
        Some("postgres://alba@db.plant:5432/history")
    );
    assert_eq!(c.s.history.password_file.as_deref(), Some("/run/secrets/pg"));
    assert_eq!(c.s.history.node.as_deref(), Some("line-2"));
    assert_eq!(c.s.history.buffer_max_samples, 1000);
    let e = parse("name = \"x\"\nprograms = [\"a.lad\"]\n[history]\nbackend = \"postgres\"\n").unwrap_err();
    assert!(e[0].contains("backend = \"postgres\" needs a url"), "{e:?}");
    let e = parse(
        "name = \"x\"\nprograms = [\"a.lad\"]\n[history]\nbackend = \"postgres\"\n\
         url = \"postgres://alba:hunter2@db:5432/h\"\n",
    )
    .unwrap_err();
    assert!(
        e[0].contains("url holds a password") && !e[0].contains("hunter2"),
        "{e:?}"
    );
    let tls = "name = \"x\"\nprograms = [\"a.lad\"]\n[history]\nbackend = \"postgres\"\nurl = \"host=db\"\n";
    let c = parse(&format!(
        "{tls}ca_file = \"certs/ca.pem\"\nclient_cert = \"certs/me.pem\"\nclient_key = \"certs/me.key\"\n"
    ))
    .unwrap();
    assert_eq!(c.s.history.ca_file.as_deref(), Some("certs/ca.pem"));
    assert_eq!(
        (c.s.history.client_cert.as_deref(), c.s.history.client_key.as_deref()),
        (Some("certs/me.pem"), Some("certs/me.key"))
    );
    let e = parse(&format!("{tls}ca_file = \"ca.pem\"\nclient_cert = \"me.pem\"\n")).unwrap_err();
    assert!(e[0].contains("client_cert and client_key go together"), "{e:?}");
    let e = parse(&format!("{tls}client_cert = \"me.pem\"\nclient_key = \"me.key\"\n")).unwrap_err();
    assert!(e[0].contains("client_cert without ca_file"), "{e:?}");
    let e = parse("name = \"x\"\nprograms = [\"a.lad\"]\n[runtime]\non_retain_error = \"ignore\"\n").unwrap_err();
    assert!(
        e[0].starts_with("alba.toml:4:19: error[E102]") && e[0].contains("unknown variant `ignore`"),
        "{e:?}"
    );
    let e =
        parse("name = \"x\"\nretain_ms = 5\nprograms = [\"a.lad\"]\n[history]\nretention_days = -1\ndeadband = -1.0\n")
            .unwrap_err();
    assert_eq!(
        e,
        [
            "alba.toml:2:13: error[E102]: retain_ms = 5 is out of range",
            "alba.toml:5:18: error[E102]: retention_days = -1 is out of range",
            "alba.toml:6:12: error[E102]: deadband = -1 is out of range",
        ]
    );
    let e = parse("name = \"x\"\nprograms = [\"a.lad\"]\n[history]\nkeep = 3\n").unwrap_err();
    assert!(e[0].contains("unknown field `keep`"), "{e:?}");
}

#[test]
fn audit_retention() {
    let c = parse("name = \"x\"\nprograms = [\"a.lad\"]\n").unwrap();
    assert_eq!(c.s.audit, Audit { retention_days: 365 });
    let c = parse("name = \"x\"\nprograms = [\"a.lad\"]\n[audit]\nretention_days = 0\n").unwrap();
    assert_eq!(c.s.audit, Audit { retention_days: 0 });
    let e = parse("name = \"x\"\nprograms = [\"a.lad\"]\n[audit]\nretention_days = 40000\n").unwrap_err();
    assert_eq!(
        e,
        ["alba.toml:4:18: error[E102]: retention_days = 40000 is out of range"]
    );
    let e = parse("name = \"x\"\nprograms = [\"a.lad\"]\n[audit]\nenabled = false\n").unwrap_err();
    assert!(e[0].contains("unknown field `enabled`"), "{e:?}");
}

#[test]
fn modbus_devices_and_their_maps() {
    let head = "name = \"x\"\nprograms = [\"a.lad\"]\n";
    let c = parse(&format!(
        "{head}[[modbus_device]]\nname = \"rack\"\ntcp = \"10.0.0.5:502\"\nmap = [\n  {{ remote = \"di 0\", count = 8, at = \"%IX0.0\" }},\n  {{ remote = \"hr 100\", at = \"AO:4/2\" }},\n]\n"
    ))
    .unwrap();
    let d = &c.c.modbus_devices[0];
    assert_eq!(
        (
            d.name.as_str(),
            &d.link,
            d.unit,
            d.poll_ms,
            d.timeout_ms,
            d.retries,
            d.refresh_ms
        ),
        ("rack", &DeviceLink::Tcp("10.0.0.5:502".into()), 1, 100, 500, 1, 1000)
    );
    let m: Vec<_> = d.map.iter().map(|m| (m.area, m.start, m.count, m.at)).collect();
    assert_eq!(
        m,
        [
            (
                ModbusArea::DiscreteInput,
                0,
                8,
                alba_model::address::Address::DigitalIn(0)
            ),
            (
                ModbusArea::HoldingRegister,
                100,
                1,
                alba_model::address::Address::AnalogOut(2)
            ),
        ]
    );
    let c = parse(&format!(
        "{head}[[modbus_device]]\nname = \"bus\"\nrtu = \"/dev/ttyUSB0\"\nbaud = 9600\n"
    ))
    .unwrap();
    assert_eq!(
        c.c.modbus_devices[0].link,
        DeviceLink::Rtu {
            port: "/dev/ttyUSB0".into(),
            baud: 9600
        }
    );
    let e = parse(&format!(
        "{head}[[modbus_device]]\nname = \"b\"\nrtu = \"/dev/x\"\ntcp = \"h:1\"\n[[modbus_device]]\nname = \"c\"\ntcp = \"h:1\"\nbaud = 9600\n"
    ))
    .unwrap_err();
    assert_eq!(
        e,
        [
            "alba.toml:6:7: error[E102]: device `b` needs exactly one of `tcp` and `rtu`",
            "alba.toml:10:8: error[E102]: `baud` is a setting of serial (rtu) devices",
        ]
    );
    let e = parse(&format!(
        "{head}[[modbus_device]]\nname = \"a\"\ntcp = \"nowhere\"\npoll_ms = 0\nunit = 300\nmap = [\n  {{ remote = \"di 0\", count = 4, at = \"AI:3/0\" }},\n  {{ remote = \"ir 0\", at = \"AO:4/0\" }},\n  {{ remote = \"coil 65535\", count = 2, at = \"DO:2/0\" }},\n  {{ remote = \"coil 0\", at = \"MW0\" }},\n  {{ remote = \"zz 1\", at = \"DI:1/0\" }},\n  {{ remote = \"di 0\", count = 2, at = \"DI:1/0\" }},\n]\n[[modbus_device]]\nname = \"a\"\ntcp = \"h:1\"\nmap = [{{ remote = \"coil 4\", at = \"DI:1/1\" }}]\n"
    ))
    .unwrap_err();
    assert_eq!(
        e,
        [
            "alba.toml:7:8: error[E102]: unit = 300 is out of range",
            "alba.toml:6:11: error[E102]: poll_ms = 0 is out of range",
            "alba.toml:5:7: error[E102]: tcp = \"nowhere\" is not a host and port",
            "alba.toml:9:38: error[E102]: bits `di 0` cannot feed `AI:3/0`",
            "alba.toml:10:14: error[E102]: `ir 0` cannot be written",
            "alba.toml:11:36: error[E102]: count = 2 is out of range",
            "alba.toml:12:29: error[E102]: `MW0` is not an I/O channel",
            "alba.toml:13:14: error[E102]: `zz 1` is not a Modbus address: expected an area (coil, di, ir, hr) and a number, like `hr 8192`",
            "alba.toml:17:8: error[E102]: two Modbus devices are named `a`",
            "alba.toml:19:34: error[E102]: channels from `DI:1/1` are already mapped by device `a`",
        ]
    );
}

#[test]
fn boards_and_pin_maps() {
    let c = parse("name = \"x\"\nprograms = [\"a.lad\"]\n[board]\nmodel = \"Nano\"\npinmap = \"s7\"\n").unwrap();
    let b = c.c.board.unwrap();
    assert_eq!((b.model, b.pinmap.as_str(), b.active_low), (Model::Nano, "s7", false));
    assert_eq!(b.map, PinMap::preset("s7").unwrap());
    // A custom list replaces one direction of the preset.
    let c = parse(
        "name = \"x\"\nprograms = [\"a.lad\"]\n[board]\nmodel = \"uno\"\nai = [\"A4\", \"A5\"]\nactive_low = true\n",
    )
    .unwrap();
    let b = c.c.board.unwrap();
    assert_eq!(b.map.ai, [Pin::A(4), Pin::A(5)]);
    assert_eq!(b.map.di, PinMap::preset("aurora").unwrap().di);
    assert!(b.active_low);
    // Outputs on at power-up: digital outputs of the map only.
    let c = parse("name = \"x\"\nprograms = [\"a.lad\"]\n[board]\nmodel = \"uno\"\npower_up_on = [\"A0\"]\n").unwrap();
    assert_eq!(c.c.board.unwrap().power_up_on, [Pin::A(0)]);
    let e = parse("name = \"x\"\nprograms = [\"a.lad\"]\n[board]\nmodel = \"uno\"\npower_up_on = [\"D2\", \"X\"]\n")
        .unwrap_err();
    assert_eq!(
        e,
        [
            "alba.toml:5:16: error[E102]: pin D2 is not a digital output of this board's pin map",
            "alba.toml:5:22: error[E102]: `X` is not a pin name",
        ]
    );
    let e = parse("name = \"x\"\nprograms = [\"a.lad\"]\n[board]\nmodel = \"due\"\n").unwrap_err();
    assert_eq!(e, ["alba.toml:4:9: error[E102]: unknown board `due`"]);
    let e = parse(
        "name = \"x\"\nprograms = [\"a.lad\"]\n[board]\nmodel = \"uno\"\nao = [\"D7\", \"Q3\", \"D9\", \"D9\"]\n",
    )
    .unwrap_err();
    assert_eq!(
        e,
        [
            "alba.toml:5:7: error[E102]: D7 has no PWM, so it cannot be an analog output",
            "alba.toml:5:13: error[E102]: `Q3` is not a pin name",
            "alba.toml:5:25: error[E102]: pin D9 is wired twice",
        ]
    );
    let e = parse("name = \"x\"\nprograms = [\"a.lad\"]\n[board]\nmodel = \"uno\"\ndi = [\"D12\"]\n").unwrap_err();
    assert_eq!(e, ["alba.toml:4:9: error[E102]: pin D12 is wired to two channels"]);
}

/// A real argon2id hash of `pw` (small parameters: a test).
fn test_hash(pw: &str) -> String {
    use argon2::password_hash::{PasswordHasher, SaltString};
    let a = argon2::Argon2::new(
        argon2::Algorithm::Argon2id,
        argon2::Version::V0x13,
        argon2::Params::new(8, 1, 1, None).unwrap(),
    );
    let salt = SaltString::encode_b64(b"alba-test-salt").unwrap();
    a.hash_password(pw.as_bytes(), &salt).unwrap().to_string()
}

#[test]
fn opcua_users_hold_argon2_hashes() {
    let h = test_hash("secret");
    let c = parse(&format!(
        "name = \"x\"\nprograms = [\"a.lad\"]\n[opcua]\nlisten = \"0.0.0.0:4840\"\n[opcua.users]\noperator = \"{h}\"\nadmin = \"{h}\"\n"
    ))
    .unwrap();
    let o = c.s.opcua.unwrap();
    assert_eq!(o.listen, Some("0.0.0.0:4840".parse().unwrap()));
    let names: Vec<_> = o.users.iter().map(|u| u.name.as_str()).collect();
    assert_eq!(names, ["operator", "admin"], "in file order");
    assert_eq!(o.users[0].hash, h);
    assert!(o.users.iter().all(|u| u.write));
    let c = parse(&format!(
        "name = \"x\"\nprograms = [\"a.lad\"]\n[opcua]\nread_only = [\"viewer\"]\n[opcua.users]\noperator = \"{h}\"\nviewer = \"{h}\"\n"
    ))
    .unwrap();
    let w: Vec<_> =
        c.s.opcua
            .unwrap()
            .users
            .iter()
            .map(|u| (u.name.clone(), u.write))
            .collect();
    assert_eq!(w, [("operator".to_string(), true), ("viewer".to_string(), false)]);
    let e = parse(&format!(
        "name = \"x\"\nprograms = [\"a.lad\"]\n[opcua]\nread_only = [\"ghost\"]\n[opcua.users]\noperator = \"{h}\"\n"
    ))
    .unwrap_err();
    assert_eq!(e, ["alba.toml:4:14: error[E102]: `ghost` is not in [opcua.users]"]);
    // Loopback needs no users.
    let c = parse("name = \"x\"\nprograms = [\"a.lad\"]\n[opcua]\nlisten = \"127.0.0.2:4840\"\n").unwrap();
    assert!(c.s.opcua.unwrap().users.is_empty());
    // Errors, each located on the offending value.
    let e = parse(&format!(
        "name = \"x\"\nprograms = [\"a.lad\"]\n[opcua]\nlisten = \"127.0.0.1:4840\"\n[opcua.users]\nplain = \"hunter2\"\nmd5 = \"$1$abc$def\"\n\"two words\" = \"{h}\"\nbroken = \"$argon2id$v=19$m=8,t=1,p=1$\"\nweak = \"$argon2id$v=19$m=1,t=1,p=1$YWxiYS10ZXN0LXNhbHQ$AAAAAAAAAAAAAAAAAAAAAA\"\n"
    ))
    .unwrap_err();
    assert_eq!(e.len(), 5, "{e:#?}");
    assert_eq!(
        e[0],
        "alba.toml:6:9: error[E102]: this is not a password hash: [opcua.users] holds argon2 hashes, never plain-text passwords"
    );
    assert!(e[1].starts_with("alba.toml:7:7: error[E102]: `$1$abc$def`"), "{}", e[1]);
    assert_eq!(e[2], "alba.toml:8:1: error[E102]: `two words` is not a user name");
    assert!(
        e[3].starts_with("alba.toml:9:10: error[E102]: `$argon2id$v=19$m=8,t=1,p=1$`"),
        "{}",
        e[3]
    );
    assert!(
        e[4].starts_with("alba.toml:10:8: error[E102]: `$argon2id$v=19$m=1,t=1,p=1$"),
        "{}",
        e[4]
    );
    // Beyond loopback without users nobody could log in (checked with the
    // project, which knows users.toml: crate::project's tests).
    let c = parse("name = \"x\"\nprograms = [\"a.lad\"]\n[opcua]\nlisten = \"0.0.0.0:4840\"\n").unwrap();
    let e = users::opcua_listen_needs_users(&c.s, false).unwrap();
    let mut files = Files::new();
    files.add(
        "alba.toml",
        "name = \"x\"\nprograms = [\"a.lad\"]\n[opcua]\nlisten = \"0.0.0.0:4840\"\n",
    );
    assert_eq!(
        e.short(&files),
        "alba.toml:4:10: error[E102]: listen = \"0.0.0.0:4840\" is not a loopback address, so it needs users"
    );
    assert!(users::opcua_listen_needs_users(&c.s, true).is_none());
    assert!(check_password_hash(&h).is_ok());
}

#[test]
fn modbus_settings_and_explicit_addresses() {
    let c = parse("name = \"x\"\nprograms = [\"a.lad\"]\n").unwrap();
    assert!(c.s.modbus.is_none() && c.s.opcua.is_none());
    let c = parse("name = \"x\"\nprograms = [\"a.lad\"]\n[opcua]\nlisten = \"127.0.0.1:4840\"\n").unwrap();
    assert_eq!(c.s.opcua.unwrap().listen, Some("127.0.0.1:4840".parse().unwrap()));
    let e = parse("name = \"x\"\nprograms = [\"a.lad\"]\n[opcua]\nlisten = \"4840\"\n").unwrap_err();
    assert_eq!(
        e,
        ["alba.toml:4:10: error[E102]: listen = \"4840\" is not an address and port"]
    );
    let c = parse(
        "name = \"x\"\nprograms = [\"a.lad\"]\n[modbus]\nlisten = \"127.0.0.1:5020\"\nunit_id = 3\n[modbus.tags]\nSpeed = \"hr 8192\"\n\"Delay.PRE\" = \"HR:9000\"\nRunning = \"coil8192\"\n",
    )
    .unwrap();
    let m = c.s.modbus.unwrap();
    assert_eq!(m.listen, Some("127.0.0.1:5020".parse().unwrap()));
    assert_eq!((m.unit_id, m.max_connections, m.idle_timeout_s), (Some(3), 32, 60));
    let tags: Vec<_> =
        c.c.modbus_tags
            .iter()
            .map(|t| (t.name.as_str(), t.area, t.start))
            .collect();
    assert_eq!(
        tags,
        [
            ("Speed", ModbusArea::HoldingRegister, 8192),
            ("Delay.PRE", ModbusArea::HoldingRegister, 9000),
            ("Running", ModbusArea::Coil, 8192),
        ]
    );
    let e = parse(
        "name = \"x\"\nprograms = [\"a.lad\"]\n[modbus]\nlisten = \"localhost\"\nmax_connections = 0\n[modbus.tags]\nA = \"hr 100\"\nB = \"xx 9000\"\nC = \"ir 70000\"\n",
    )
    .unwrap_err();
    assert_eq!(
        e,
        [
            // The project's tables are checked first, then the services'.
            "alba.toml:7:5: error[E102]: `hr 100` is inside OpenPLC's map (hr 0 to 8191, which the I/O image and markers use)",
            "alba.toml:8:5: error[E102]: `xx 9000` is not a Modbus address: expected an area (coil, di, ir, hr) and a number, like `hr 8192`",
            "alba.toml:9:5: error[E102]: `ir 70000`: Modbus addresses go from 0 to 65535",
            "alba.toml:4:10: error[E102]: listen = \"localhost\" is not an address and port",
            "alba.toml:5:19: error[E102]: max_connections = 0 is out of range",
        ]
    );
}

#[test]
fn bad_configs_are_located() {
    let e = parse("name = \"x\"\nscan_m = 5\nprograms = [\"a.lad\"]\n").unwrap_err();
    assert!(
        e[0].starts_with("alba.toml:2:1: error[E102]: alba.toml: unknown field `scan_m`"),
        "{e:?}"
    );
    let e = parse("name = \"x\"\nscan_ms = 0\nprograms = []\n").unwrap_err();
    assert_eq!(
        e,
        [
            "alba.toml:2:11: error[E102]: scan_ms = 0 is out of range",
            "alba.toml:3:12: error[E102]: `programs` is empty"
        ]
    );
    let e = parse("name = \"x\nprograms = [\"a.lad\"]\n").unwrap_err();
    assert!(e[0].contains("error[E101]"), "{e:?}");
    let e = parse("programs = [\"a.lad\"]\n").unwrap_err();
    assert!(e[0].contains("missing field `name`"), "{e:?}");
    let e = parse("name = 5\nprograms = [\"a.lad\"]\n").unwrap_err();
    assert!(e[0].starts_with("alba.toml:1:8: error[E102]"), "{e:?}");
}

#[test]
fn plant_models_are_checked_with_their_places() {
    let head = "name = \"p\"\nprograms = [\"a.lad\"]\n";
    let ok = format!(
        "{head}[[plant_model]]\nkind = \"first_order\"\ninput = \"AO:4/0\"\noutput = \"AI:3/0\"\ntau = 10.0\ninput_scale = [0, 10000, 0, 10]\ndead_time = 0.5\n"
    );
    let c = parse(&ok).unwrap();
    assert_eq!(c.c.models.len(), 1);
    assert_eq!(c.c.models[0].dead_time, 0.5);
    let bad = format!(
        "{head}[[plant_model]]\nkind = \"first_order\"\ninput = \"U\"\noutput = \"Y\"\ntau = -1.0\narea = 2.0\nsaturation = [5, 1]\n\n[[plant_model]]\nkind = \"third\"\ninput = \"U\"\noutput = \"Y\"\n\n[[plant_model]]\nkind = \"second_order\"\ninput = \"U\"\noutput = \"Y\"\nden = [1, 2]\n"
    );
    let e = parse(&bad).unwrap_err();
    assert_eq!(
        e,
        [
            "alba.toml:7:7: error[E105]: tau = -1 must be a number more than 0",
            "alba.toml:8:8: error[E105]: `area` is not a parameter of a first_order model",
            "alba.toml:9:14: error[E105]: saturation must be [lo, hi] with lo <= hi",
            "alba.toml:12:8: error[E105]: unknown plant model kind `third`",
            "alba.toml:20:7: error[E105]: den must be three numbers [a2, a1, a0] for gain/(a2·s² + a1·s + a0)",
        ]
    );
}

#[test]
fn modbus_allow_list_and_read_only() {
    let head = "name = \"x\"\nprograms = [\"a.lad\"]\n[modbus]\n";
    // Off by default: no list (every loopback client), writes allowed.
    let m = parse(&format!("{head}listen = \"127.0.0.1:5020\"\n"))
        .unwrap()
        .s
        .modbus
        .unwrap();
    assert_eq!((m.allow, m.read_only), (None, false));
    let m = parse(&format!(
        "{head}listen = \"0.0.0.0:502\"\nread_only = true\nallow = [\"192.168.1.20\", \"10.0.0.0/24\", \"fd00::/8\", \"::1\", \"0.0.0.0/0\"]\n"
    ))
    .unwrap()
    .s.modbus
    .unwrap();
    assert!(m.read_only);
    let allow = m.allow.unwrap();
    let shown: Vec<String> = allow.iter().map(ToString::to_string).collect();
    assert_eq!(shown, ["192.168.1.20", "10.0.0.0/24", "fd00::/8", "::1", "0.0.0.0/0"]);
    let ip = |s: &str| s.parse::<std::net::IpAddr>().unwrap();
    assert!(allow[0].contains(ip("192.168.1.20")) && !allow[0].contains(ip("192.168.1.21")));
    assert!(allow[1].contains(ip("10.0.0.255")) && !allow[1].contains(ip("10.0.1.0")));
    // An IPv4 client seen on an IPv6 socket is its IPv4 address.
    assert!(allow[1].contains(ip("::ffff:10.0.0.7")));
    assert!(allow[2].contains(ip("fd12::1")) && !allow[2].contains(ip("fe80::1")));
    assert!(allow[3].contains(ip("::1")) && !allow[3].contains(ip("127.0.0.1")));
    assert!(allow[4].contains(ip("8.8.8.8")) && !allow[4].contains(ip("2001:db8::1")));
    // IPv6 listeners beyond loopback need the list too; `::1` does not.
    assert!(parse(&format!("{head}listen = \"[::1]:502\"\n")).is_ok());
}

#[test]
fn bad_modbus_client_rules_are_located() {
    let head = "name = \"x\"\nprograms = [\"a.lad\"]\n[modbus]\n";
    let e = parse(&format!(
        "{head}listen = \"127.0.0.1:502\"\nallow = [\"10.0.0.0/33\", \"10.0.0.5/24\", \"host.lan\", \"fd00::/129\", \"1.2.3.4/x\"]\n"
    ))
    .unwrap_err();
    assert_eq!(
        e,
        [
            "alba.toml:5:10: error[E108]: `10.0.0.0/33`: the prefix length of an IPv4 range goes from 0 to 32",
            "alba.toml:5:25: error[E108]: `10.0.0.5/24` has bits set after its /24 prefix: the range is `10.0.0.0/24`",
            "alba.toml:5:40: error[E108]: `host.lan` is not an IP address or a CIDR range (like \"192.168.1.20\" or \"10.0.0.0/24\")",
            "alba.toml:5:52: error[E108]: `fd00::/129`: the prefix length of an IPv6 range goes from 0 to 128",
            "alba.toml:5:66: error[E108]: `1.2.3.4/x`: the prefix length of an IPv4 range goes from 0 to 32",
        ]
    );
    let e = parse(&format!("{head}listen = \"0.0.0.0:502\"\n")).unwrap_err();
    assert_eq!(
        e,
        ["alba.toml:4:10: error[E108]: listen = \"0.0.0.0:502\" is not a loopback address, so it needs `allow`"]
    );
    let e = parse(&format!("{head}listen = \"[::]:502\"\n")).unwrap_err();
    assert_eq!(
        e,
        ["alba.toml:4:10: error[E108]: listen = \"[::]:502\" is not a loopback address, so it needs `allow`"]
    );
    let e = parse(&format!("{head}allow = []\n")).unwrap_err();
    assert_eq!(e, ["alba.toml:4:9: error[E108]: allow = [] lets no client in"]);
    let e = parse(&format!("{head}read_only = \"yes\"\n")).unwrap_err();
    assert!(e[0].starts_with("alba.toml:4:13: error[E102]"), "{e:?}");
}

#[test]
fn http_table_lists_hosts_origins_and_tls_files() {
    let head = "name = \"x\"\nprograms = [\"a.lad\"]\n";
    assert_eq!(parse(head).unwrap().s.http, Http::default());
    let c = parse(&format!(
        "{head}[http]\nallowed_hosts = [\"PLC1.plant.example\"]\nallowed_origins = [\"https://scada.example:8443\", \"http://[::1]:8080\"]\ninsecure = true\ncert = \"tls/c.pem\"\nkey = \"tls/k.pem\"\n"
    ))
    .unwrap();
    assert_eq!(c.s.http.allowed_hosts, ["plc1.plant.example"]);
    assert_eq!(
        c.s.http.allowed_origins,
        ["https://scada.example:8443", "http://[::1]:8080"]
    );
    assert!(c.s.http.insecure);
    assert_eq!(
        (c.s.http.cert.as_deref(), c.s.http.key.as_deref()),
        (Some("tls/c.pem"), Some("tls/k.pem"))
    );
    for (bad, what) in [
        ("allowed_hosts = [\"http://plc1\"]", "not a host name"),
        ("allowed_hosts = [\"plc1:8080\"]", "not a host name"),
        ("allowed_origins = [\"scada.example\"]", "not an origin"),
        ("allowed_origins = [\"ftp://scada.example\"]", "not an origin"),
        ("allowed_origins = [\"http://scada.example:99999\"]", "not an origin"),
        ("cert = \"c.pem\"", "both `cert` and `key`"),
    ] {
        let e = parse(&format!("{head}[http]\n{bad}\n")).unwrap_err();
        assert!(e.iter().any(|m| m.contains(what)), "{bad}: {e:?}");
    }
}

#[test]
fn authorities_split_into_host_and_port() {
    assert_eq!(split_authority("localhost:8080"), Some(("localhost", Some(8080))));
    assert_eq!(split_authority("plc1"), Some(("plc1", None)));
    assert_eq!(split_authority("[::1]:80"), Some(("[::1]", Some(80))));
    assert_eq!(split_authority("[::1]"), Some(("[::1]", None)));
    for bad in ["", "a:b", "::1", "[zz]:1", "a b", "h:", "evil.example/x"] {
        assert_eq!(split_authority(bad), None, "{bad}");
    }
}

#[test]
fn a_reports_table_is_the_settings_and_not_the_project() {
    let c =
        parse("name = \"t\"\nprograms = [\"main.lad\"]\n[reports]\nshift_hours = [6, 14, 22]\nformats = [\"xlsx\"]\n")
            .expect("both readers take it");
    let r = c.s.reports.expect("[reports]");
    assert_eq!((r.shift_hours, r.folder.as_str()), (vec![6, 14, 22], "reports"));
    let e = parse("name = \"t\"\nprograms = [\"main.lad\"]\n[reports]\nperiod_hours = 7\n").unwrap_err();
    assert!(e.iter().any(|d| d.contains("does not divide a day")), "{e:?}");
}

#[test]
fn mqtt_and_alarms_tables() {
    let c = parse("name = \"t\"\nprograms = [\"main.lad\"]\n").unwrap();
    assert_eq!((c.s.mqtt, c.s.alarms.retention_days), (None, 365));
    let c = parse(
        "name = \"t\"\nprograms = [\"main.lad\"]\n[alarms]\nretention_days = 30\n[mqtt]\nbroker = \"broker.local:8883\"\n\
         topic_prefix = \"site/line1\"\nqos = 0\ntags = [\"Level\", \"Delay\"]\nwrites = false\n\
         username = \"plc\"\npassword_file = \"mqtt.secret\"\n",
    )
    .unwrap();
    let m = c.s.mqtt.unwrap();
    assert_eq!(c.s.alarms.retention_days, 30);
    assert_eq!(m.broker.as_deref(), Some("broker.local:8883"));
    assert_eq!(m.topic_prefix.as_deref(), Some("site/line1"));
    assert_eq!((m.qos, m.writes, m.keep_alive_s, m.queue), (0, false, 30, 10_000));
    assert_eq!(m.tags, ["Level", "Delay"]);
    assert_eq!((m.publish_interval_ms, m.deadband), (0, 0.0));
    let m2 = parse("name = \"t\"\nprograms = [\"main.lad\"]\n[mqtt]\npublish_interval_ms = 250\ndeadband = 0.5\n")
        .unwrap()
        .s
        .mqtt
        .unwrap();
    assert_eq!((m2.publish_interval_ms, m2.deadband), (250, 0.5));
    assert_eq!(m2.version, alba_settings::MqttVersion::V311);
    for (v, want) in [
        ("5", alba_settings::MqttVersion::V5),
        ("\"5.0\"", alba_settings::MqttVersion::V5),
        ("\"3.1.1\"", alba_settings::MqttVersion::V311),
        ("4", alba_settings::MqttVersion::V311),
    ] {
        let m = parse(&format!(
            "name = \"t\"\nprograms = [\"main.lad\"]\n[mqtt]\nversion = {v}\n"
        ))
        .unwrap()
        .s
        .mqtt
        .unwrap();
        assert_eq!(m.version, want, "{v}");
    }
    let m3 = parse(
        "name = \"t\"\nprograms = [\"main.lad\"]\n[mqtt]\nuser = \"line1\"\npassword_file = \"/run/secrets/mqtt\"\n",
    )
    .unwrap()
    .s
    .mqtt
    .unwrap();
    assert_eq!(
        (m3.user.as_deref(), m3.username, m3.password_file.as_deref()),
        (Some("line1"), None, Some("/run/secrets/mqtt"))
    );
    assert_eq!(
        (m.username.as_deref(), m.password_file.as_deref()),
        (Some("plc"), Some("mqtt.secret"))
    );
    let e = parse(
        "name = \"t\"\nprograms = [\"main.lad\"]\n[mqtt]\nbroker = \"x:0\"\nqos = 3\nkeep_alive_s = 1\nsecret = 1\n",
    )
    .unwrap_err();
    assert!(e.iter().any(|d| d.contains("unknown field `secret`")), "{e:?}");
    for bad in [
        "broker = \"x:0\"",
        "qos = 3",
        "keep_alive_s = 1",
        "topic_prefix = \"a/+/b\"",
        "topic_prefix = \"a/\"",
        "queue = 5",
        "publish_interval_ms = -1",
        "deadband = -0.5",
        "deadband = nan",
        "user = \"op\"",
        "user = \"op\"\nusername = \"x\"\npassword_file = \"f\"",
        "username = \"x\"",
        "version = 3",
        "version = \"3.1\"",
    ] {
        let e = parse(&format!("name = \"t\"\nprograms = [\"main.lad\"]\n[mqtt]\n{bad}\n")).unwrap_err();
        assert!(e.iter().any(|d| d.contains("E102")), "{bad}: {e:?}");
    }
}

#[test]
fn mqtt_sparkplug_table() {
    let head = "name = \"t\"\nprograms = [\"main.lad\"]\n[mqtt]\n[mqtt.sparkplug]\n";
    let sp = parse(head).unwrap().s.mqtt.unwrap().sparkplug.unwrap();
    assert_eq!(
        (
            sp.group_id.as_str(),
            sp.edge_node_id,
            sp.device_id.as_str(),
            sp.primary_host_id,
            sp.buffer_max
        ),
        ("alba", None, "plc", None, 1_000_000)
    );
    assert!(sp.devices.is_empty());
    let sp = parse(&format!(
        "{head}primary_host_id = \"scada\"\nbuffer_max = 5000\n[mqtt.sparkplug.devices]\npumps = [\"P1\", \"P2\"]\nline = [\"Conveyor\"]\n"
    ))
        .unwrap()
        .s.mqtt
        .unwrap()
        .sparkplug
        .unwrap();
    assert_eq!((sp.primary_host_id.as_deref(), sp.buffer_max), (Some("scada"), 5000));
    assert_eq!(
        sp.devices,
        [
            ("line".to_string(), vec!["Conveyor".to_string()]),
            ("pumps".to_string(), vec!["P1".to_string(), "P2".to_string()])
        ]
    );
    for bad in [
        "primary_host_id = \"a/b\"",
        "buffer_max = 1",
        "group_id = \"\"",
        "devices = { \"a+b\" = [\"X\"] }",
    ] {
        let e = parse(&format!("{head}{bad}\n")).unwrap_err();
        assert!(e.iter().any(|d| d.contains("E102")), "{bad}: {e:?}");
    }
}

#[test]
fn opcua_servers_and_their_bindings() {
    let head = "name = \"x\"\nprograms = [\"a.lad\"]\n";
    let c = parse(&format!(
        "{head}[[opcua_server]]\nname = \"plc\"\nendpoint = \"opc.tcp://10.0.0.9:4840/\"\nsecurity_policy = \"Basic256Sha256\"\nuser = \"op\"\npassword_file = \"secret.txt\"\nbind = [\n  {{ tag = \"Level\", node = \"ns=2;s=Tank.Level\", dir = \"in\" }},\n  {{ tag = \"Pump\", node = \"ns=3;i=1001\", dir = \"out\" }},\n]\n"
    ))
    .unwrap();
    let s = &c.s.opcua_servers[0];
    assert_eq!(
        (
            s.name.as_str(),
            s.endpoint.as_str(),
            s.policy,
            s.mode,
            s.user.clone(),
            s.pki_dir.as_str(),
            s.publishing_interval_ms
        ),
        (
            "plc",
            "opc.tcp://10.0.0.9:4840/",
            SecurityPolicy::Basic256Sha256,
            SecurityMode::SignAndEncrypt,
            Some(("op".to_string(), "secret.txt".to_string())),
            DEFAULT_CLIENT_PKI,
            100
        )
    );
    let b: Vec<_> = s
        .bindings
        .iter()
        .map(|b| (b.tag.as_str(), b.node.as_str(), b.dir))
        .collect();
    assert_eq!(
        b,
        [
            ("Level", "ns=2;s=Tank.Level", Direction::In),
            ("Pump", "ns=3;i=1001", Direction::Out)
        ]
    );
    let e = parse(&format!(
        "{head}[[opcua_server]]\nname = \"a\"\nendpoint = \"http://x\"\nsecurity_policy = \"Basic128\"\nsecurity_mode = \"Sign\"\nuser = \"op\"\npublishing_interval_ms = 0\nbind = [\n  {{ tag = \"A\", node = \"ns=x;s=A\", dir = \"in\" }},\n  {{ tag = \"A\", node = \"ns=2;s=A\", dir = \"up\" }},\n  {{ tag = \"A\", node = \"ns=2;s=A\", dir = \"in\" }},\n  {{ tag = \"A\", node = \"ns=2;s=B\", dir = \"in\" }},\n]\n[[opcua_server]]\nname = \"a\"\nendpoint = \"opc.tcp://h:4840\"\nsecurity_mode = \"Sign\"\n"
    ))
    .unwrap_err();
    assert_eq!(
        e,
        [
            "alba.toml:5:12: error[E102]: endpoint = \"http://x\" is not an OPC UA address",
            "alba.toml:6:19: error[E102]: security_policy = \"Basic128\" is not known",
            "alba.toml:7:17: error[E102]: security_policy None does not go with security_mode Sign",
            "alba.toml:8:8: error[E102]: `user` and `password_file` go together",
            "alba.toml:9:26: error[E102]: publishing_interval_ms = 0 is out of range",
            "alba.toml:11:23: error[E102]: `ns=x;s=A` is not a node id",
            "alba.toml:12:41: error[E102]: dir = \"up\" is not a direction",
            "alba.toml:14:11: error[E102]: tag `A` is already fed by server `a`",
            "alba.toml:17:8: error[E102]: two OPC UA servers are named `a`",
            "alba.toml:19:17: error[E102]: security_policy None does not go with security_mode Sign",
        ]
    );
    assert!(is_node_id("i=85") && is_node_id("nsu=urn:x;s=A.B") && !is_node_id("ns=1") && !is_node_id("s="));
}
