//! The node manager of Alba's OPC UA server: async-opcua's simple node
//! manager, which calls a write callback with the value only, wrapped so
//! that the callback knows whose session writes. [`Manager::write`] sets
//! the session's user and role ([`writer`]) for the time of the inner
//! write, during which the callbacks run (synchronously); the write's audit
//! row then names `opcua:<user>` (docs/audit.md, "Doors"). The client's
//! address is not known to any node manager: async-opcua drops it when it
//! accepts the connection.

use alba_auth::{Role, Users};
use async_trait::async_trait;
use opcua::server::CreateMonitoredItem;
use opcua::server::address_space::AddressSpace;
use opcua::server::diagnostics::NamespaceMetadata;
use opcua::server::node_manager::memory::{
    InMemoryNodeManager, InMemoryNodeManagerBuilder, InMemoryNodeManagerImpl, InMemoryNodeManagerImplBuilder,
    SimpleNodeManagerBuilder, SimpleNodeManagerImpl,
};
use opcua::server::node_manager::{
    MethodCall, MonitoredItemRef, MonitoredItemUpdateRef, NodeManagerBuilder, ParsedReadValueId, RequestContext,
    ServerContext, WriteNode,
};
use opcua::sync::RwLock;
use opcua::types::{DataValue, MonitoringMode, StatusCode, TimestampsToReturn};
use std::sync::Arc;

/// Who writes: the session's user (`None`: anonymous) and role.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Writer {
    pub user: Option<String>,
    pub role: Role,
}

tokio::task_local! {
    static WRITER: Writer;
}

/// The session whose write is being applied; `None` outside a write.
pub fn writer() -> Option<Writer> {
    WRITER.try_with(Writer::clone).ok()
}

/// The simple node manager, and the users who may log in.
pub struct Manager {
    inner: SimpleNodeManagerImpl,
    users: Arc<Users>,
}

/// The node manager as the server holds it.
pub type AlbaNodeManager = InMemoryNodeManager<Manager>;

impl Manager {
    /// The simple node manager (its read and write callbacks).
    pub fn simple(&self) -> &SimpleNodeManagerImpl {
        &self.inner
    }
}

struct Builder {
    simple: SimpleNodeManagerBuilder,
    users: Arc<Users>,
}

impl InMemoryNodeManagerImplBuilder for Builder {
    type Impl = Manager;

    fn build(self, context: ServerContext, address_space: &mut AddressSpace) -> Manager {
        Manager {
            inner: self.simple.build(context, address_space),
            users: self.users,
        }
    }
}

/// The node manager of namespace `namespace`, for `users`.
pub fn node_manager(namespace: NamespaceMetadata, name: &str, users: Arc<Users>) -> impl NodeManagerBuilder {
    InMemoryNodeManagerBuilder::new(Builder {
        simple: SimpleNodeManagerBuilder::new(namespace, name),
        users,
    })
}

#[async_trait]
impl InMemoryNodeManagerImpl for Manager {
    async fn init(&self, address_space: &mut AddressSpace, context: ServerContext) {
        self.inner.init(address_space, context).await;
    }

    fn name(&self) -> &str {
        self.inner.name()
    }

    fn namespaces(&self) -> Vec<NamespaceMetadata> {
        self.inner.namespaces()
    }

    async fn read_values(
        &self,
        context: &RequestContext,
        address_space: &RwLock<AddressSpace>,
        nodes: &[&ParsedReadValueId],
        max_age: f64,
        timestamps_to_return: TimestampsToReturn,
    ) -> Vec<DataValue> {
        self.inner
            .read_values(context, address_space, nodes, max_age, timestamps_to_return)
            .await
    }

    async fn create_value_monitored_items(
        &self,
        context: &RequestContext,
        address_space: &RwLock<AddressSpace>,
        items: &mut [&mut &mut CreateMonitoredItem],
    ) {
        self.inner
            .create_value_monitored_items(context, address_space, items)
            .await;
    }

    async fn set_monitoring_mode(&self, context: &RequestContext, mode: MonitoringMode, items: &[&MonitoredItemRef]) {
        self.inner.set_monitoring_mode(context, mode, items).await;
    }

    async fn modify_monitored_items(&self, context: &RequestContext, items: &[&MonitoredItemUpdateRef]) {
        self.inner.modify_monitored_items(context, items).await;
    }

    async fn delete_monitored_items(&self, context: &RequestContext, items: &[&MonitoredItemRef]) {
        self.inner.delete_monitored_items(context, items).await;
    }

    /// The inner write, with the session's user and role set for its
    /// callbacks. Anonymous sessions may write only when the project has no
    /// users (`security::Auth`): they act as operators, as before.
    async fn write(
        &self,
        context: &RequestContext,
        address_space: &RwLock<AddressSpace>,
        nodes_to_write: &mut [&mut WriteNode],
    ) -> Result<(), StatusCode> {
        let writer = if context.token.is_anonymous() {
            Writer {
                user: None,
                role: Role::Operator,
            }
        } else {
            Writer {
                user: Some(context.token.0.clone()),
                role: self.users.role(&context.token.0).unwrap_or(Role::Viewer),
            }
        };
        WRITER
            .scope(writer, self.inner.write(context, address_space, nodes_to_write))
            .await
    }

    async fn call(
        &self,
        context: &RequestContext,
        address_space: &RwLock<AddressSpace>,
        methods_to_call: &mut [&mut &mut MethodCall],
    ) -> Result<(), StatusCode> {
        self.inner.call(context, address_space, methods_to_call).await
    }
}
