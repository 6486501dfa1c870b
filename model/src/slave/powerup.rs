//! The power-up communication state machine. // 000:T9, 000:2.4.1, 002:57h, DESIGN:power-up

use crate::profile::Profile;
use crate::settings::UartSettings;

/// The states of 000 Table 9.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum CommState {
    /// No UART communication.
    Initialization,
    /// Default settings (9600, even, long timeout) until the default window ends.
    DefaultCommunication,
    /// A request arrived in the default window: default settings until reset.
    OperationalDefault,
    /// No UART communication while switching to the stored settings.
    ChangeOfSettings,
    /// The stored (user-defined) settings.
    OperationalUser,
}

impl CommState {
    /// The state's names, longest first: 000 Table 9's, then shorter ones for less
    /// room (a timing diagram's box); one table, so that every writer says the same.
    pub const fn names(self) -> [&'static str; 3] {
        match self {
            CommState::Initialization => ["Initialization", "Initialization", "Init."],
            CommState::DefaultCommunication => ["Default Communication", "Default Communication", "Default"],
            CommState::OperationalDefault => {
                ["Operational (default communication)", "Operational (default)", "Op. (default)"]
            }
            CommState::ChangeOfSettings => ["Change of communication settings", "Change of settings", "Change"],
            CommState::OperationalUser => {
                ["Operational (user-defined communication)", "Operational (user-defined)", "Op. (user)"]
            }
        }
    }

    /// The state's name in 000 Table 9.
    pub const fn name(self) -> &'static str {
        self.names()[0]
    }
}

/// Where the slave is since its last power-on or reset.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct PowerUp {
    /// Power-on or reset time, µs; `None` when powered on long before any time of
    /// interest (all windows over).
    pub since_us: Option<u64>,
    /// A request addressed to the slave arrived in the default window.
    pub kept_default: bool,
}

impl PowerUp {
    pub const fn at(since_us: u64) -> PowerUp {
        PowerUp { since_us: Some(since_us), kept_default: false }
    }

    /// Powered on long ago: Operational with the stored settings.
    pub const fn settled() -> PowerUp {
        PowerUp { since_us: None, kept_default: false }
    }

    pub fn state(&self, profile: &Profile, now_us: u64) -> CommState {
        let Some(since) = self.since_us else {
            return if self.kept_default { CommState::OperationalDefault } else { CommState::OperationalUser };
        };
        let ms = |m: u16| since.saturating_add(m as u64 * 1000);
        if now_us < ms(profile.init_ms) {
            CommState::Initialization
        } else if self.kept_default {
            CommState::OperationalDefault
        } else if now_us < ms(profile.default_window_ms) {
            CommState::DefaultCommunication
        } else if now_us < ms(profile.user_settings_ms) {
            CommState::ChangeOfSettings
        } else {
            CommState::OperationalUser
        }
    }

    /// The settings the slave listens with, `None` when it does not listen.
    pub fn settings(&self, profile: &Profile, now_us: u64, stored: UartSettings) -> Option<UartSettings> {
        match self.state(profile, now_us) {
            CommState::DefaultCommunication | CommState::OperationalDefault => Some(UartSettings::DEFAULT),
            CommState::OperationalUser => Some(stored),
            CommState::Initialization | CommState::ChangeOfSettings => None,
        }
    }

    /// The next time the state changes by itself, if any.
    pub fn next_change(&self, profile: &Profile, now_us: u64) -> Option<u64> {
        let since = self.since_us?;
        [profile.init_ms, profile.default_window_ms, profile.user_settings_ms]
            .iter()
            .map(|m| since.saturating_add(*m as u64 * 1000))
            .find(|t| *t > now_us)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::profiles;

    #[test]
    fn each_state_has_table_9s_name_first_and_shorter_ones_after() {
        let states = [
            CommState::Initialization,
            CommState::DefaultCommunication,
            CommState::OperationalDefault,
            CommState::ChangeOfSettings,
            CommState::OperationalUser,
        ];
        assert_eq!(
            states.map(CommState::name),
            [
                "Initialization",
                "Default Communication",
                "Operational (default communication)",
                "Change of communication settings",
                "Operational (user-defined communication)",
            ]
        );
        assert_eq!(states.map(|s| s.names()[2]), ["Init.", "Default", "Op. (default)", "Change", "Op. (user)"]);
        for s in states {
            let [long, short, shortest] = s.names();
            assert!(long.len() >= short.len() && short.len() > shortest.len(), "{long}");
        }
    }

    #[test]
    fn table_9_timeline() {
        let p = profiles::srs50();
        let mut up = PowerUp::at(0);
        assert_eq!(up.state(&p, 99_999), CommState::Initialization);
        assert_eq!(up.state(&p, 100_000), CommState::DefaultCommunication);
        assert_eq!(up.state(&p, 899_999), CommState::DefaultCommunication);
        assert_eq!(up.state(&p, 900_000), CommState::ChangeOfSettings);
        assert_eq!(up.state(&p, 1_100_000), CommState::OperationalUser);
        assert_eq!(up.next_change(&p, 950_000), Some(1_100_000));
        up.kept_default = true;
        assert_eq!(up.state(&p, 5_000_000), CommState::OperationalDefault);
        let legacy = profiles::legacy_srs();
        let up = PowerUp::at(0);
        assert_eq!(up.state(&legacy, 999_999), CommState::DefaultCommunication);
        assert_eq!(up.state(&legacy, 1_000_000), CommState::OperationalUser);
        assert_eq!(PowerUp::settled().state(&legacy, 0), CommState::OperationalUser);
    }
}
