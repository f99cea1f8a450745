//! Sparkplug B 3.0 (Eclipse Tahu) without I/O: the payload as protobuf
//! ([`proto`], written with `prost` derives from Tahu's `sparkplug_b.proto`),
//! topics ([`Topic`]), data types, and [`EdgeNode`], the state of one edge
//! node that builds its NBIRTH/DBIRTH/DDATA/NDEATH messages with their
//! sequence numbers and aliases. `alba run` (crates/app/src/sparkplug/) moves
//! these bytes over MQTT; tests decode them with a third-party library.

pub mod proto;

use prost::Message as _;

use proto::{Metric, Payload, metric};
use std::collections::HashMap;

/// The namespace of every Sparkplug B topic.
pub const NAMESPACE: &str = "spBv1.0";
/// The metric a host writes `true` to for a rebirth.
pub const REBIRTH: &str = "Node Control/Rebirth";
/// The birth/death sequence metric.
pub const BD_SEQ: &str = "bdSeq";

/// Sparkplug B data types (the `datatype` field of a metric).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u32)]
pub enum DataType {
    Int8 = 1,
    Int16 = 2,
    Int32 = 3,
    Int64 = 4,
    UInt8 = 5,
    UInt16 = 6,
    UInt32 = 7,
    UInt64 = 8,
    Float = 9,
    Double = 10,
    Boolean = 11,
    String = 12,
}

/// A metric's value, as Alba's types carry it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Value {
    Bool(bool),
    Int8(i8),
    Int16(i16),
    Int32(i32),
    Int64(i64),
    UInt64(u64),
    Float(f32),
    Double(f64),
}

impl Value {
    pub fn datatype(self) -> DataType {
        match self {
            Value::Bool(_) => DataType::Boolean,
            Value::Int8(_) => DataType::Int8,
            Value::Int16(_) => DataType::Int16,
            Value::Int32(_) => DataType::Int32,
            Value::Int64(_) => DataType::Int64,
            Value::UInt64(_) => DataType::UInt64,
            Value::Float(_) => DataType::Float,
            Value::Double(_) => DataType::Double,
        }
    }

    /// The protobuf value: signed integers up to 32 bits in `int_value` as
    /// their two's complement (Sparkplug 3.0, §6.4.16), 64-bit ones in
    /// `long_value`.
    fn encode(self) -> metric::Value {
        match self {
            Value::Bool(b) => metric::Value::BooleanValue(b),
            Value::Int8(x) => metric::Value::IntValue(u32::from(x as u8)),
            Value::Int16(x) => metric::Value::IntValue(u32::from(x as u16)),
            Value::Int32(x) => metric::Value::IntValue(x as u32),
            Value::Int64(x) => metric::Value::LongValue(x as u64),
            Value::UInt64(x) => metric::Value::LongValue(x),
            Value::Float(x) => metric::Value::FloatValue(x),
            Value::Double(x) => metric::Value::DoubleValue(x),
        }
    }

    /// A received value read as `datatype`, or why it cannot be.
    pub fn decode(datatype: u32, v: &metric::Value) -> Result<Value, SparkplugError> {
        use metric::Value as V;
        Ok(match (datatype, v) {
            (11, V::BooleanValue(b)) => Value::Bool(*b),
            (1, V::IntValue(x)) => Value::Int8(*x as u8 as i8),
            (2, V::IntValue(x)) => Value::Int16(*x as u16 as i16),
            (3, V::IntValue(x)) => Value::Int32(*x as i32),
            (4, V::LongValue(x)) => Value::Int64(*x as i64),
            (8, V::LongValue(x)) => Value::UInt64(*x),
            (9, V::FloatValue(x)) => Value::Float(*x),
            (10, V::DoubleValue(x)) => Value::Double(*x),
            (t, v) => {
                return Err(SparkplugError::Unsupported {
                    datatype: t,
                    value: format!("{v:?}"),
                });
            }
        })
    }
}

/// A Sparkplug B topic: `spBv1.0/<group>/<type>/<edge node>[/<device>]`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Topic {
    pub group: String,
    pub kind: String,
    pub node: String,
    pub device: Option<String>,
}

impl Topic {
    pub fn parse(s: &str) -> Option<Topic> {
        let mut it = s.split('/');
        if it.next()? != NAMESPACE {
            return None;
        }
        let (group, kind, node) = (it.next()?, it.next()?, it.next()?);
        let device = it.next().map(str::to_string);
        if it.next().is_some() || [group, kind, node].iter().any(|p| p.is_empty()) || device.as_deref() == Some("") {
            return None;
        }
        Some(Topic {
            group: group.into(),
            kind: kind.into(),
            node: node.into(),
            device,
        })
    }
}

/// Whether an id may appear in a topic: no `/`, `+`, `#`, not empty.
pub fn valid_id(s: &str) -> bool {
    !s.is_empty() && !s.contains(['/', '+', '#'])
}

/// One edge node and its devices, their metrics named and aliased at birth.
#[derive(Debug, Clone)]
pub struct EdgeNode {
    pub group: String,
    pub node: String,
    /// Birth/death sequence: the NDEATH registered with a connection carries
    /// the value its NBIRTH will (Sparkplug 3.0 §6.4.2); +1 per connection.
    bd_seq: u64,
    /// Message sequence, 0–255, wrapping; NBIRTH is 0.
    seq: u64,
    /// Metric name → alias, unique in the node across its devices (stable
    /// for the life of the node).
    aliases: HashMap<String, u64>,
    names: Vec<String>,
    /// The metrics of the last birth: each one's device and data type
    /// (commands may omit the type).
    born: HashMap<String, (String, u32)>,
}

impl EdgeNode {
    pub fn new(group: &str, node: &str) -> EdgeNode {
        EdgeNode {
            group: group.into(),
            node: node.into(),
            bd_seq: 0,
            seq: 0,
            aliases: HashMap::new(),
            names: Vec::new(),
            born: HashMap::new(),
        }
    }

    /// The topic of a node message: NBIRTH, NDATA, NDEATH, NCMD.
    pub fn topic(&self, kind: &str) -> String {
        format!("{NAMESPACE}/{}/{kind}/{}", self.group, self.node)
    }

    /// The topic of a device message: DBIRTH, DDATA, DDEATH, DCMD (`+`: every device).
    pub fn device_topic(&self, kind: &str, device: &str) -> String {
        format!("{NAMESPACE}/{}/{kind}/{}/{device}", self.group, self.node)
    }

    fn next_seq(&mut self) -> u64 {
        let s = self.seq;
        self.seq = (self.seq + 1) % 256;
        s
    }

    /// The last message built was not sent (the client's queue was full):
    /// its `seq` goes to the next one, so that hosts see no gap.
    pub fn not_sent(&mut self) {
        self.seq = (self.seq + 255) % 256;
    }

    pub fn bd_seq(&self) -> u64 {
        self.bd_seq
    }

    /// Starts from the bdSeq of the last session (kept across restarts):
    /// the next connection gets the next one.
    pub fn resume_after(&mut self, last_bd_seq: u64) {
        self.bd_seq = (last_bd_seq + 1) % 256;
    }

    /// The NDEATH to register as the last will of the next connection
    /// (it carries the bdSeq that connection's NBIRTH will).
    pub fn death(&self, now_ms: u64) -> Vec<u8> {
        Payload {
            timestamp: Some(now_ms),
            metrics: vec![bd_seq_metric(self.bd_seq)],
            seq: None,
            ..Default::default()
        }
        .encode_to_vec()
    }

    /// NBIRTH and one DBIRTH per device for a new connection (or a
    /// rebirth): the node's metrics (bdSeq, Node Control/Rebirth) and every
    /// device metric with its name, alias, type and value. `seq` restarts at
    /// 0. A metric name is one metric of the node: if two devices list it,
    /// the first has it.
    pub fn birth(
        &mut self,
        now_ms: u64,
        devices: &[(String, Vec<(String, Value)>)],
    ) -> (Vec<u8>, Vec<(String, Vec<u8>)>) {
        self.seq = 0;
        let nbirth = Payload {
            timestamp: Some(now_ms),
            metrics: vec![
                bd_seq_metric(self.bd_seq),
                Metric {
                    name: Some(REBIRTH.into()),
                    timestamp: Some(now_ms),
                    datatype: Some(DataType::Boolean as u32),
                    value: Some(metric::Value::BooleanValue(false)),
                    ..Default::default()
                },
            ],
            seq: Some(self.next_seq()),
            ..Default::default()
        };
        self.born.clear();
        let mut dbirths = Vec::new();
        for (device, metrics) in devices {
            let mut born = Vec::new();
            for (name, v) in metrics {
                if self.born.contains_key(name) {
                    continue;
                }
                self.born.insert(name.clone(), (device.clone(), v.datatype() as u32));
                if !self.aliases.contains_key(name) {
                    self.aliases.insert(name.clone(), self.names.len() as u64);
                    self.names.push(name.clone());
                }
                born.push(Metric {
                    name: Some(name.clone()),
                    alias: self.aliases.get(name).copied(),
                    timestamp: Some(now_ms),
                    datatype: Some(v.datatype() as u32),
                    value: Some(v.encode()),
                    ..Default::default()
                });
            }
            let dbirth = Payload {
                timestamp: Some(now_ms),
                metrics: born,
                seq: Some(self.next_seq()),
                ..Default::default()
            };
            dbirths.push((device.clone(), dbirth.encode_to_vec()));
        }
        (nbirth.encode_to_vec(), dbirths)
    }

    /// The device a metric was born in.
    pub fn device_of(&self, name: &str) -> Option<&str> {
        self.born.get(name).map(|(d, _)| d.as_str())
    }

    /// The connection is gone: the next one gets the next bdSeq.
    pub fn disconnected(&mut self) {
        self.bd_seq = (self.bd_seq + 1) % 256;
    }

    /// A DDATA of changed metrics of `device`, by alias only (names and data
    /// types were in the DBIRTH, so neither is sent again, as Sparkplug 3.0
    /// §6.4.5 advises). A name not born in this device is refused (the
    /// caller rebirths).
    pub fn data(&mut self, device: &str, now_ms: u64, changes: &[(String, Value)]) -> Option<Vec<u8>> {
        let metrics = changes
            .iter()
            .map(|(name, v)| {
                (self.device_of(name) == Some(device))
                    .then(|| self.data_metric(name, *v, now_ms, false))
                    .flatten()
            })
            .collect::<Option<Vec<_>>>()?;
        Some(self.data_payload(now_ms, metrics))
    }

    /// A DDATA of stored values of `device` (store and forward): each
    /// metric flagged `is_historical` with the time it had the value, so a
    /// host records it without taking it for the current value. Values of
    /// metrics the current birth does not have in this device, or has with
    /// another data type (the program or the devices changed while they
    /// waited), are left out: the second member counts them. `None` when
    /// none is left.
    pub fn historical(&mut self, device: &str, t_ms: u64, values: &[(String, Value)]) -> (Option<Vec<u8>>, usize) {
        let metrics: Vec<Metric> = values
            .iter()
            .filter(|(name, v)| self.born.get(name) == Some(&(device.to_string(), v.datatype() as u32)))
            .filter_map(|(name, v)| self.data_metric(name, *v, t_ms, true))
            .collect();
        let left_out = values.len() - metrics.len();
        if metrics.is_empty() {
            return (None, left_out);
        }
        (Some(self.data_payload(t_ms, metrics)), left_out)
    }

    fn data_metric(&self, name: &str, v: Value, t_ms: u64, historical: bool) -> Option<Metric> {
        Some(Metric {
            alias: Some(*self.aliases.get(name)?),
            timestamp: Some(t_ms),
            is_historical: historical.then_some(true),
            value: Some(v.encode()),
            ..Default::default()
        })
    }

    fn data_payload(&mut self, t_ms: u64, metrics: Vec<Metric>) -> Vec<u8> {
        Payload {
            timestamp: Some(t_ms),
            metrics,
            seq: Some(self.next_seq()),
            ..Default::default()
        }
        .encode_to_vec()
    }

    /// The metrics of an NCMD/DCMD: (name, value) each, aliases resolved.
    pub fn command(&self, payload: &[u8]) -> Result<Vec<(String, Value)>, SparkplugError> {
        let p = Payload::decode(payload).map_err(|e| SparkplugError::NotAPayload(e.to_string()))?;
        p.metrics
            .iter()
            .map(|m| {
                let name = match (&m.name, m.alias) {
                    (Some(n), _) => n.clone(),
                    (None, Some(a)) => self
                        .names
                        .get(a as usize)
                        .cloned()
                        .ok_or(SparkplugError::UnknownAlias(a))?,
                    (None, None) => return Err(SparkplugError::Unnamed),
                };
                let value = m.value.as_ref().ok_or_else(|| SparkplugError::NoValue(name.clone()))?;
                let datatype = m
                    .datatype
                    .or_else(|| self.datatype_of(&name))
                    .ok_or_else(|| SparkplugError::NoDataType(name.clone()))?;
                Ok((
                    name.clone(),
                    Value::decode(datatype, value).map_err(|e| SparkplugError::Metric {
                        name: name.clone(),
                        source: Box::new(e),
                    })?,
                ))
            })
            .collect()
    }

    fn datatype_of(&self, name: &str) -> Option<u32> {
        match name {
            REBIRTH => Some(DataType::Boolean as u32),
            _ => self.born.get(name).map(|(_, t)| *t),
        }
    }
}

/// Why a Sparkplug message or record cannot be read.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum SparkplugError {
    #[error("a value {value} of data type {datatype} is not supported")]
    Unsupported { datatype: u32, value: String },
    #[error("not a Sparkplug B payload: {0}")]
    NotAPayload(String),
    #[error("unknown alias {0}")]
    UnknownAlias(u64),
    #[error("a metric without a name or an alias")]
    Unnamed,
    #[error("`{0}` has no value")]
    NoValue(String),
    #[error("`{0}` has no data type")]
    NoDataType(String),
    #[error("`{name}`: {source}")]
    Metric { name: String, source: Box<SparkplugError> },
    #[error("a STATE payload is JSON ({0})")]
    StateNotJson(String),
    #[error("a STATE payload needs `online`: true or false")]
    StateOnline,
    #[error("a STATE payload needs `timestamp`: ms since 1970")]
    StateTimestamp,
    #[error("not a buffered record: {0}")]
    NotARecord(String),
    #[error("a buffered metric without a name")]
    RecordUnnamed,
    #[error("buffered `{0}` without a type or a value")]
    RecordIncomplete(String),
}

/// Any Sparkplug B payload (a host's view: tests, benchmarks, tools).
pub fn decode_payload(bytes: &[u8]) -> Result<Payload, SparkplugError> {
    Payload::decode(bytes).map_err(|e| SparkplugError::NotAPayload(e.to_string()))
}

/// The topic of a Sparkplug host application's `STATE` (3.0 §4.2.2).
pub fn state_topic(host_id: &str) -> String {
    format!("{NAMESPACE}/STATE/{host_id}")
}

/// A host application's `STATE` message: `{"online": bool, "timestamp": ms}`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct HostState {
    pub online: bool,
    pub timestamp: u64,
}

impl HostState {
    /// The JSON payload of a `STATE` message, or why it is not one.
    pub fn parse(payload: &[u8]) -> Result<HostState, SparkplugError> {
        let j: serde_json::Value =
            serde_json::from_slice(payload).map_err(|e| SparkplugError::StateNotJson(e.to_string()))?;
        let online = j
            .get("online")
            .and_then(serde_json::Value::as_bool)
            .ok_or(SparkplugError::StateOnline)?;
        let timestamp = j
            .get("timestamp")
            .and_then(serde_json::Value::as_u64)
            .ok_or(SparkplugError::StateTimestamp)?;
        Ok(HostState { online, timestamp })
    }
}

/// What an edge node makes of its primary host's `STATE` messages
/// (Sparkplug 3.0 §5.3, §5.4): a message older than the last one that
/// counted is an echo of an earlier session and changes nothing.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct PrimaryHost {
    /// Online as of the last message that counted.
    pub online: bool,
    /// The timestamp of the last message that counted, and of the last online one.
    last: Option<u64>,
    last_online: Option<u64>,
}

impl PrimaryHost {
    /// Takes a `STATE` message; whether it counted (the host's state is now `online`).
    pub fn update(&mut self, s: HostState) -> bool {
        let counts = if s.online {
            // Online: not older than any STATE before it.
            self.last.is_none_or(|t| s.timestamp >= t)
        } else {
            // Offline: not older than the online message it ends (a will
            // carries its birth's timestamp).
            self.last_online.is_none_or(|t| s.timestamp >= t)
        };
        if counts {
            self.online = s.online;
            self.last = Some(self.last.map_or(s.timestamp, |t| t.max(s.timestamp)));
            if s.online {
                self.last_online = Some(s.timestamp);
            }
        }
        counts
    }
}

/// A record of the store-and-forward buffer: the values a snapshot changed
/// and its time, as a Sparkplug payload with metric names (aliases and
/// sequence numbers are the session's, given when it is sent).
pub fn encode_record(t_ms: u64, values: &[(String, Value)]) -> Vec<u8> {
    Payload {
        timestamp: Some(t_ms),
        metrics: values
            .iter()
            .map(|(name, v)| Metric {
                name: Some(name.clone()),
                datatype: Some(v.datatype() as u32),
                value: Some(v.encode()),
                ..Default::default()
            })
            .collect(),
        ..Default::default()
    }
    .encode_to_vec()
}

/// A record written by [`encode_record`], or why the bytes are not one.
pub fn decode_record(bytes: &[u8]) -> Result<(u64, Vec<(String, Value)>), SparkplugError> {
    let p = Payload::decode(bytes).map_err(|e| SparkplugError::NotARecord(e.to_string()))?;
    let values = p
        .metrics
        .iter()
        .map(|m| {
            let name = m.name.clone().ok_or(SparkplugError::RecordUnnamed)?;
            let (Some(t), Some(v)) = (m.datatype, &m.value) else {
                return Err(SparkplugError::RecordIncomplete(name));
            };
            Ok((name, Value::decode(t, v)?))
        })
        .collect::<Result<Vec<_>, SparkplugError>>()?;
    Ok((p.timestamp.unwrap_or(0), values))
}

fn bd_seq_metric(v: u64) -> Metric {
    Metric {
        name: Some(BD_SEQ.into()),
        datatype: Some(DataType::Int64 as u32),
        value: Some(metric::Value::LongValue(v)),
        ..Default::default()
    }
}
