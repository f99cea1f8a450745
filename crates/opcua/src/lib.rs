//! Alba's OPC UA server (SPEC §9, docs/protocols.md), on `async-opcua`.
//!
//! Every tag of the running program is a typed variable node under
//! `Objects/Alba/<project>/Tags` (node ids `ns=<alba>;s=<tag name>`); a
//! TIMER or COUNTER is an object whose members are variables
//! (`s=Delay.PRE`). The scan statistics and system tags are read-only
//! variables under `Objects/Alba/<project>/System`. Reads and subscription
//! samples come from the runtime's latest snapshot; a write goes to the
//! engine thread and is answered once applied between two scans, through
//! the control layer (`alba-control`: the rules and the audit row of every
//! door; refusals mapped by [`status`]). Inputs, status members and system
//! tags are read-only (their access level says so, and async-opcua refuses
//! a write to them with `BadUserAccessDenied`).
//! Security ([`security`]): `None` with anonymous access only when bound to
//! a loopback address; Basic256Sha256 (Sign, SignAndEncrypt) with the user
//! names and argon2-hashed passwords of the project's user store
//! (`alba_auth::Users`: users.toml) always, and alone elsewhere; viewers
//! write nothing. The server's certificate is created in the PKI folder on
//! first run.

pub mod client;
pub mod manager;
pub mod security;

pub use alba_control::Control;
use alba_control::{Actor, Refused};
use alba_ir::{Access, Place, Target};
use alba_model::{DataType, Value};
use alba_runtime::Handle;
use manager::AlbaNodeManager;
use opcua::nodes::{AccessLevel, ObjectBuilder, VariableBuilder};
use opcua::server::ServerBuilder;
use opcua::server::diagnostics::NamespaceMetadata;
use opcua::types::{
    DataTypeId, DataValue, DateTime, NodeId, NumericRange, ObjectId, QualifiedName, StatusCode, TimestampsToReturn,
    Variant,
};
use std::net::SocketAddr;
use std::path::PathBuf;

/// The namespace of a project's nodes.
pub fn namespace_uri(project: &str) -> String {
    format!("urn:alba:{project}")
}

/// The OPC UA type of an Alba type.
fn data_type(t: DataType) -> DataTypeId {
    match t {
        DataType::Bool => DataTypeId::Boolean,
        DataType::Sint => DataTypeId::SByte,
        DataType::Int => DataTypeId::Int16,
        DataType::Lint => DataTypeId::Int64,
        DataType::Real => DataTypeId::Float,
        DataType::Lreal => DataTypeId::Double,
        // DINT and TIME (milliseconds).
        _ => DataTypeId::Int32,
    }
}

fn variant(v: Value) -> Variant {
    match v {
        Value::Bool(b) => Variant::Boolean(b),
        Value::Sint(x) => Variant::SByte(x),
        Value::Int(x) => Variant::Int16(x),
        Value::Dint(x) | Value::Time(x) => Variant::Int32(x),
        Value::Lint(x) => Variant::Int64(x),
        Value::Real(x) => Variant::Float(x),
        Value::Lreal(x) => Variant::Double(x),
    }
}

/// A written variant as the JSON value the control layer checks (its
/// type and range against the tag's: the same rules as every door);
/// `None` for a variant no tag takes (strings, arrays, non-finite reals).
fn json_of(v: &Variant) -> Option<serde_json::Value> {
    use serde_json::Value as J;
    Some(match v {
        Variant::Boolean(b) => J::Bool(*b),
        Variant::SByte(x) => J::from(*x),
        Variant::Byte(x) => J::from(*x),
        Variant::Int16(x) => J::from(*x),
        Variant::UInt16(x) => J::from(*x),
        Variant::Int32(x) => J::from(*x),
        Variant::UInt32(x) => J::from(*x),
        Variant::Int64(x) => J::from(*x),
        Variant::UInt64(x) => J::from(*x),
        Variant::Float(x) if x.is_finite() => J::from(f64::from(*x)),
        Variant::Double(x) if x.is_finite() => J::from(*x),
        _ => return None,
    })
}

/// The status code that answers a refusal of the control layer (the one
/// place where OPC UA meets its rules).
pub fn status(r: &Refused) -> StatusCode {
    match r {
        Refused::UnknownTag(_) | Refused::UnknownAlarm(_) | Refused::NotForced(_) => StatusCode::BadNodeIdUnknown,
        Refused::NotWritable(_) | Refused::NotForceable(_) => StatusCode::BadNotWritable,
        Refused::WrongType(_) => StatusCode::BadTypeMismatch,
        Refused::OutOfRange(_) => StatusCode::BadOutOfRange,
        Refused::Role { .. } => StatusCode::BadUserAccessDenied,
        Refused::AuditUnavailable(_) => StatusCode::BadResourceUnavailable,
        Refused::Runtime(_) | Refused::NotApplied(_) => StatusCode::BadServerHalted,
        Refused::Alarm(_) => StatusCode::BadInvalidState,
        Refused::Internal(_) => StatusCode::BadInternalError,
    }
}

/// The place and access of `name` in the latest program (resolved at each
/// use, so the node follows its tag through online edits).
fn resolve(handle: &Handle, name: &str) -> Option<(Place, Access)> {
    match handle.snapshot().program.layout.resolve(name) {
        Ok(Target::Value { place, access }) => Some((place, access)),
        _ => None,
    }
}

fn read_cb(
    handle: Handle,
    name: String,
) -> impl Fn(&NumericRange, TimestampsToReturn, f64) -> Result<DataValue, StatusCode> + Send + Sync + 'static {
    move |_, _, _| {
        let snap = handle.snapshot();
        let Ok(Target::Value { place, .. }) = snap.program.layout.resolve(&name) else {
            return Err(StatusCode::BadNodeIdUnknown);
        };
        let now = DateTime::now();
        Ok(DataValue {
            value: Some(variant(snap.read(place))),
            status: Some(StatusCode::Good),
            source_timestamp: Some(now),
            server_timestamp: Some(now),
            ..Default::default()
        })
    }
}

fn write_cb(control: Control, name: String) -> impl Fn(DataValue, &NumericRange) -> StatusCode + Send + Sync + 'static {
    move |dv, range| {
        if !matches!(range, NumericRange::None) {
            return StatusCode::BadIndexRangeInvalid;
        }
        let Some(v) = dv.value.as_ref().and_then(json_of) else {
            return StatusCode::BadTypeMismatch;
        };
        // The session's user and role (`manager::Manager::write` sets them
        // for the time of the write); no peer: the library does not keep the
        // client's address (docs/audit.md, "Doors").
        let Some(w) = manager::writer() else {
            return StatusCode::BadInternalError; // a write outside `Manager::write`
        };
        let actor = Actor::opcua(w.user.as_deref(), w.role, None);
        // Answered once the engine thread applied it between two scans
        // (at most one scan's wait; this worker thread is handed over).
        let c = control.clone();
        let done = match tokio::runtime::Handle::try_current() {
            Ok(rt) if rt.runtime_flavor() == tokio::runtime::RuntimeFlavor::MultiThread => {
                tokio::task::block_in_place(|| rt.block_on(c.write(&actor, &name, &v)))
            }
            _ => return StatusCode::BadServerHalted, // no multi-threaded runtime
        };
        match done {
            Ok(_) => StatusCode::Good,
            Err(r) => status(&r),
        }
    }
}

/// Adds one variable for `name` (a tag, member or system tag) under `parent`.
fn add_variable(nm: &AlbaNodeManager, ns: u16, control: &Control, name: &str, browse: &str, parent: &NodeId) {
    let handle = control.runtime();
    let Some((place, access)) = resolve(handle, name) else {
        return;
    };
    let id = NodeId::new(ns, name.to_string());
    let writable = access == Access::ReadWrite;
    let level = if writable {
        AccessLevel::CURRENT_READ | AccessLevel::CURRENT_WRITE
    } else {
        AccessLevel::CURRENT_READ
    };
    let initial = variant(handle.snapshot().read(place));
    {
        let mut space = nm.address_space().write();
        VariableBuilder::new(&id, QualifiedName::new(ns, browse), browse)
            .data_type(data_type(place.data_type()))
            .value(initial)
            .access_level(level)
            .user_access_level(level)
            .component_of(parent.clone())
            .insert(&mut *space);
    }
    nm.inner()
        .simple()
        .add_read_callback(id.clone(), read_cb(handle.clone(), name.to_string()));
    if writable {
        nm.inner()
            .simple()
            .add_write_callback(id, write_cb(control.clone(), name.to_string()));
    }
}

/// Starts the server on `listener`'s address (the listener itself is
/// handed to the server). Returns once it serves; it stops when `closing`
/// turns true.
pub async fn serve(
    control: Control,
    project: &str,
    addr: SocketAddr,
    pki_dir: PathBuf,
    users: std::sync::Arc<alba_auth::Users>,
    mut closing: tokio::sync::watch::Receiver<bool>,
) -> Result<SocketAddr, String> {
    if !security::is_local(addr.ip()) && users.is_empty() {
        return Err(format!(
            "OPC UA on {addr} (not loopback) serves only Basic256Sha256 with a user name and password, and the project has no users (users.toml, or the deprecated [opcua.users] of alba.toml): add one with `alba user add <project> <name> --role operator` (docs/security.md) or listen on 127.0.0.1"
        ));
    }
    let listener = tokio::net::TcpListener::bind(addr)
        .await
        .map_err(|e| format!("cannot listen for OPC UA on {addr}: {e}"))?;
    let bound = listener.local_addr().map_err(|e| e.to_string())?;
    let uri = namespace_uri(project);
    security::protect_private_key(&pki_dir)?;
    let local = security::is_local(bound.ip());
    let mut builder = ServerBuilder::new()
        .application_name("Alba")
        .with_authenticator(std::sync::Arc::new(security::Auth::new(bound.ip(), users.clone())))
        // Loopback: only this machine can connect, its client certificates
        // are trusted on first use; elsewhere an unknown certificate is
        // refused and kept in pki/rejected/ for an administrator to trust.
        .trust_client_certs(local);
    for (id, endpoint) in security::endpoints(bound.ip()) {
        builder = builder.add_endpoint(id, endpoint);
    }
    let (server, sh) = builder
        .default_endpoint(if local { "none" } else { "basic256sha256_sign_encrypt" })
        .application_uri("urn:alba")
        .product_uri("urn:alba")
        .host(bound.ip().to_string())
        .port(bound.port())
        .pki_dir(pki_dir.clone())
        .create_sample_keypair(true)
        .discovery_urls(vec![format!("opc.tcp://{bound}/")])
        .with_node_manager(manager::node_manager(
            NamespaceMetadata {
                namespace_uri: uri.clone(),
                ..Default::default()
            },
            "alba",
            users.clone(),
        ))
        .build()?;
    security::protect_private_key(&pki_dir)?;
    let nm = sh
        .node_managers()
        .get_of_type::<AlbaNodeManager>()
        .ok_or("the OPC UA node manager is missing")?;
    let ns = sh.get_namespace_index(&uri).ok_or("the OPC UA namespace is missing")?;
    let alba = NodeId::new(ns, "Alba");
    let proj = NodeId::new(ns, format!("Alba/{project}"));
    let tags = NodeId::new(ns, format!("Alba/{project}/Tags"));
    let system = NodeId::new(ns, format!("Alba/{project}/System"));
    {
        let mut space = nm.address_space().write();
        let q = |n: &str| QualifiedName::new(ns, n);
        space.add_folder(&alba, q("Alba"), "Alba", &ObjectId::ObjectsFolder.into());
        space.add_folder(&proj, q(project), project, &alba);
        space.add_folder(&tags, q("Tags"), "Tags", &proj);
        space.add_folder(&system, q("System"), "System", &proj);
    }
    let handle = control.runtime();
    let snap = handle.snapshot();
    for tag in snap.program.layout.tags.iter() {
        if tag.ty.members().is_empty() {
            add_variable(&nm, ns, &control, &tag.name, &tag.name, &tags);
            continue;
        }
        let obj = NodeId::new(ns, tag.name.clone());
        {
            let mut space = nm.address_space().write();
            ObjectBuilder::new(&obj, QualifiedName::new(ns, tag.name.as_str()), tag.name.as_str())
                .organized_by(tags.clone())
                .insert(&mut *space);
        }
        for m in tag.ty.members() {
            add_variable(&nm, ns, &control, &format!("{}.{}", tag.name, m.name), m.name, &obj);
        }
    }
    for (name, _) in alba_ir::layout::SYSTEM_TAGS {
        add_variable(&nm, ns, &control, name, name, &system);
    }
    let token = sh.token().clone();
    tokio::spawn(async move {
        while !*closing.borrow() {
            if closing.changed().await.is_err() {
                break;
            }
        }
        token.cancel();
    });
    tokio::spawn(async move {
        if let Err(e) = server.run_with(listener).await {
            eprintln!("OPC UA server: {e}");
        }
    });
    Ok(bound)
}
