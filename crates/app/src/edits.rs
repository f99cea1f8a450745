//! Follows the studio's saved edits (the server's "program replaced"
//! hook): one line on the console per edit, so the operator running
//! `alba run` sees what changed under them.

use crate::{Service, Started};

pub(crate) fn start(s: &Service<'_>) -> Started {
    let mut edits = s.state.subscribe_edits();
    let mut closing = s.state.closing();
    tokio::spawn(async move {
        loop {
            tokio::select! {
                _ = closing.wait_for(|c| *c) => return,
                e = edits.recv() => match e {
                    Ok(e) => println!(
                        "studio: saved {}{}",
                        e.file,
                        if e.applied { ", applied online" } else { "" }
                    ),
                    Err(tokio::sync::broadcast::error::RecvError::Lagged(_)) => continue,
                    Err(tokio::sync::broadcast::error::RecvError::Closed) => return,
                },
            }
        }
    });
    Started::On
}
