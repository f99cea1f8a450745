//! The kinds of audited actions and their stable names.

use std::fmt;
use std::str::FromStr;

use crate::error::Error;

macro_rules! actions {
    ($($(#[$doc:meta])* $variant:ident = $name:literal,)*) => {
        /// What was done. Each kind has a stable name (stored in the log, used in the API
        /// and the CSV export); new kinds may be added, names never change.
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
        pub enum Action {
            $($(#[$doc])* $variant,)*
        }

        impl Action {
            /// Every kind, in declaration order.
            pub const ALL: &'static [Action] = &[$(Action::$variant,)*];

            /// The stable name.
            pub fn name(self) -> &'static str {
                match self {
                    $(Action::$variant => $name,)*
                }
            }
        }
    };
}

actions! {
    /// A tag written (`PUT /api/tags/{name}`): old and new value.
    Write = "write",
    /// An I/O point forced: the value before (or the former force) and the forced value.
    Force = "force",
    /// A force removed (target `None`: every force).
    Unforce = "unforce",
    /// A program saved without applying it: detail holds the diff summary.
    SaveProgram = "save_program",
    /// A program saved and applied to the running PLC: detail holds the diff summary.
    OnlineEdit = "online_edit",
    /// The tag table (tags.csv) saved and applied: detail holds the diff summary.
    SaveTags = "save_tags",
    /// The PLC put in run.
    Run = "run",
    /// The PLC stopped.
    Stop = "stop",
    /// A successful login.
    Login = "login",
    /// A failed login (the user is the name tried).
    LoginFailed = "login_failed",
    /// A logout.
    Logout = "logout",
    /// A user added (target: the user; new: the role).
    UserAdded = "user_added",
    /// A user's role or password changed (target: the user).
    UserChanged = "user_changed",
    /// A user removed (target: the user).
    UserRemoved = "user_removed",
    /// An alarm acknowledged (target: the alarm).
    AlarmAck = "alarm_ack",
    /// An alarm shelved (target: the alarm; detail: minutes and reason).
    AlarmShelve = "alarm_shelve",
    /// An alarm's shelving ended by an operator.
    AlarmUnshelve = "alarm_unshelve",
    /// An alarm taken out of service or put back (new: true or false; detail: reason).
    AlarmOutOfService = "alarm_out_of_service",
    /// The studio's trend set saved (`trends.json`; detail: the pens).
    SaveTrends = "save_trends",
    /// A SCADA screen saved (`hmi/<name>.json`).
    SaveScreen = "save_screen",
    /// One scan run while the PLC is stopped (single step).
    Step = "step",
    /// A net's marking reset to its initial marking (target: the net).
    ResetMarking = "reset_marking",
    /// The board and pin map saved (`[board]` of alba.toml; detail: the new settings).
    SaveBoard = "save_board",
    /// The project's byte code downloaded to a board (target: the serial port).
    Download = "download",
    /// A recipe saved (`recipes/<name>.csv`; new: its entries as a JSON object).
    SaveRecipe = "save_recipe",
    /// An image saved into the project (`hmi/assets/<name>`; detail: its type and size).
    SaveAsset = "save_asset",
    /// A board attached as the running PLC's I/O (target: the serial port;
    /// old → new: the I/O driver before and after; detail: the mode).
    Attach = "attach",
    /// The attached board let go, the project's own I/O back (target: the serial port).
    Detach = "detach",
    /// A firmware built and uploaded with avrdude (target: the serial port; detail: the board and kind).
    Upload = "upload",
    /// A scheduled shift report written to `[reports] folder` (target: the
    /// file; detail: the shift, UTC). Nobody's: `user` is empty.
    Report = "report",
}

impl fmt::Display for Action {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Action {
    type Err = Error;

    /// The kind named `s` (exactly as [`Action::name`] spells it).
    fn from_str(s: &str) -> Result<Action, Error> {
        Action::ALL.iter().copied().find(|a| a.name() == s).ok_or_else(|| {
            let names: Vec<&str> = Action::ALL.iter().map(|a| a.name()).collect();
            Error::InvalidArgument(format!("unknown action `{s}` (one of: {})", names.join(", ")))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_unique_and_round_trip() {
        let mut seen = std::collections::HashSet::new();
        for &a in Action::ALL {
            assert!(seen.insert(a.name()), "duplicate name {a}");
            assert_eq!(a.name().parse::<Action>().expect("parses"), a);
        }
        assert!("Write".parse::<Action>().is_err());
        assert!("".parse::<Action>().is_err());
    }

    /// The names are stored in audit logs: changing one breaks old files.
    #[test]
    fn names_are_stable() {
        let names: Vec<&str> = Action::ALL.iter().map(|a| a.name()).collect();
        assert_eq!(
            names,
            [
                "write",
                "force",
                "unforce",
                "save_program",
                "online_edit",
                "save_tags",
                "run",
                "stop",
                "login",
                "login_failed",
                "logout",
                "user_added",
                "user_changed",
                "user_removed",
                "alarm_ack",
                "alarm_shelve",
                "alarm_unshelve",
                "alarm_out_of_service",
                "save_trends",
                "save_screen",
                "step",
                "reset_marking",
                "save_board",
                "download",
                "save_recipe",
                "save_asset",
                "attach",
                "detach",
                "upload",
                "report"
            ]
        );
    }
}
