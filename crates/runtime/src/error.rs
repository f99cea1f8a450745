//! The runtime's typed errors: of an I/O driver ([`IoError`], the error of
//! the [`crate::Io`] trait) and of starting the runtime ([`StartError`]).
//! (Refusals of requests to a running runtime are [`crate::Error`].)

/// Why an I/O driver could not read, write or apply an operator's write.
/// The variant says what happened (and what a driver does about it: reopen
/// the link, retry, give up); the message is the one shown to the user.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum IoError {
    /// The driver's link thread has ended: nothing can be sent any more.
    #[error("the link to the board has stopped")]
    LinkStopped,
    /// The link itself failed or cannot be opened (a serial port unplugged,
    /// a TCP connection lost): the driver reopens it. The message says how.
    #[error("{0}")]
    Link(String),
    /// No link at the moment: the request was not sent (with the last failure).
    #[error("no link to the board: {0}")]
    NoLink(Box<IoError>),
    /// No answer, or no valid one, in time (a timeout, a bad frame): worth retrying.
    #[error("{0}")]
    Timeout(String),
    /// The device did not confirm an operator's write in time.
    #[error("the board did not confirm the write within {secs} s")]
    WriteTimeout { secs: u64 },
    /// The device refused the request (a Modbus exception reply): retrying
    /// does not help.
    #[error("{0}")]
    Refused(String),
    /// A valid answer of another kind than the request asked for.
    #[error("unexpected answer {0}")]
    UnexpectedAnswer(String),
    /// The value cannot be written there on the device (a type the board
    /// does not have or a place that cannot hold it).
    #[error("{0}")]
    DoesNotFit(String),
    /// The device is not the one the project expects (another program, not
    /// an Alba sketch): the runtime stops with this message.
    #[error("{0}")]
    WrongDevice(String),
    /// Memory read from the device does not have the program's sizes.
    #[error("{0}")]
    MemoryMismatch(String),
}

impl IoError {
    /// The link is gone (reopen it) rather than one request failed.
    pub fn is_link_down(&self) -> bool {
        matches!(self, IoError::Link(_) | IoError::LinkStopped | IoError::NoLink(_))
    }
}

/// Why [`crate::Runtime::start`] failed.
#[derive(Debug, thiserror::Error)]
pub enum StartError {
    /// The program does not verify (or its native code cannot be built).
    #[error(transparent)]
    Program(#[from] alba_engine::EngineError),
    /// The retain file cannot be read or is not one (it is left alone).
    #[error(transparent)]
    Retain(#[from] crate::retain::RetainError),
    /// A thread of the runtime could not be started.
    #[error("cannot start the {what} thread: {source}")]
    Thread {
        what: &'static str,
        #[source]
        source: std::io::Error,
    },
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages_and_link_state() {
        let lost = IoError::Link("serial port: end of file".into());
        assert!(lost.is_link_down() && IoError::LinkStopped.is_link_down());
        assert!(!IoError::Timeout("no answer within 30 ms".into()).is_link_down());
        assert!(!IoError::Refused("the board refused".into()).is_link_down());
        assert_eq!(
            IoError::NoLink(Box::new(lost)).to_string(),
            "no link to the board: serial port: end of file"
        );
        assert_eq!(
            IoError::WriteTimeout { secs: 3 }.to_string(),
            "the board did not confirm the write within 3 s"
        );
        assert_eq!(IoError::LinkStopped.to_string(), "the link to the board has stopped");
        assert_eq!(
            IoError::UnexpectedAnswer("Written".into()).to_string(),
            "unexpected answer Written"
        );
    }
}
