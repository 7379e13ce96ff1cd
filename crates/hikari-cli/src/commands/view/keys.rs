//! The viewer's key bindings: which key does what, in one table that the panel's help and
//! docs/viewer.md show.

use winit::keyboard::KeyCode;

/// A movement key's direction.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Move {
    Forward,
    Left,
    Back,
    Right,
    Down,
    Up,
}

/// What a key press does (besides movement, which lasts while the key is held).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Action {
    Exit,
    TogglePanel,
    Screenshot,
    /// The clock 30 minutes back.
    TimeBack,
    /// The clock 30 minutes on.
    TimeForward,
    /// Plays or stops the clock.
    PlayClock,
    /// Ray-traced GI on or off.
    ToggleGi,
    /// The next debug view.
    NextView,
    /// Back to the final image.
    FinalView,
    /// The scene's camera of this index (0 for key 1).
    Camera(usize),
}

/// The movement a key gives while held (physical keys: the same places on any layout).
pub fn movement(key: KeyCode) -> Option<Move> {
    Some(match key {
        KeyCode::KeyW => Move::Forward,
        KeyCode::KeyA => Move::Left,
        KeyCode::KeyS => Move::Back,
        KeyCode::KeyD => Move::Right,
        KeyCode::KeyQ => Move::Down,
        KeyCode::KeyE => Move::Up,
        _ => return None,
    })
}

/// The action of a key pressed, with Shift held or not.
pub fn action(key: KeyCode, shift: bool) -> Option<Action> {
    const DIGITS: [KeyCode; 9] = [
        KeyCode::Digit1,
        KeyCode::Digit2,
        KeyCode::Digit3,
        KeyCode::Digit4,
        KeyCode::Digit5,
        KeyCode::Digit6,
        KeyCode::Digit7,
        KeyCode::Digit8,
        KeyCode::Digit9,
    ];
    Some(match key {
        KeyCode::Escape => Action::Exit,
        KeyCode::F1 => Action::TogglePanel,
        KeyCode::F12 => Action::Screenshot,
        KeyCode::BracketLeft => Action::TimeBack,
        KeyCode::BracketRight => Action::TimeForward,
        KeyCode::KeyP => Action::PlayClock,
        KeyCode::KeyT => Action::ToggleGi,
        KeyCode::KeyV if shift => Action::FinalView,
        KeyCode::KeyV => Action::NextView,
        k => Action::Camera(DIGITS.iter().position(|&d| d == k)?),
    })
}

/// Every binding as (keys, what they do), in the order the help shows them.
pub const KEY_TABLE: &[(&str, &str)] = &[
    ("W / A / S / D", "move forward / left / back / right"),
    ("Q / E", "move down / up"),
    ("Shift (held)", "move five times faster"),
    ("mouse wheel", "movement speed up / down"),
    ("right mouse button + drag", "look around"),
    ("1 to 9", "jump to the scene's named camera (a camera cut)"),
    ("[ / ]", "clock 30 minutes back / on"),
    ("P", "play / stop the clock"),
    ("T", "ray-traced GI on / off"),
    ("V", "next debug view"),
    ("Shift + V", "back to the final image"),
    ("F1", "hide / show the panel"),
    (
        "F12",
        "screenshot: PNG and linear EXR in the working folder",
    ),
    ("Esc", "quit"),
];

/// The movement keys held now.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Held {
    keys: [bool; 6],
}

impl Held {
    fn index(m: Move) -> usize {
        m as usize
    }

    pub fn set(&mut self, m: Move, down: bool) {
        self.keys[Self::index(m)] = down;
    }

    pub fn is(&self, m: Move) -> bool {
        self.keys[Self::index(m)]
    }

    /// Lets go of every key (the window lost the focus and will not see them released).
    pub fn clear(&mut self) {
        self.keys = [false; 6];
    }

    /// The held directions as (right, up, forward), each -1, 0 or 1.
    pub fn axes(&self) -> [f32; 3] {
        let axis = |pos: Move, neg: Move| self.is(pos) as i32 as f32 - self.is(neg) as i32 as f32;
        [
            axis(Move::Right, Move::Left),
            axis(Move::Up, Move::Down),
            axis(Move::Forward, Move::Back),
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_issues_keys_do_what_it_says() {
        assert_eq!(movement(KeyCode::KeyW), Some(Move::Forward));
        assert_eq!(movement(KeyCode::KeyA), Some(Move::Left));
        assert_eq!(movement(KeyCode::KeyS), Some(Move::Back));
        assert_eq!(movement(KeyCode::KeyD), Some(Move::Right));
        assert_eq!(movement(KeyCode::KeyQ), Some(Move::Down));
        assert_eq!(movement(KeyCode::KeyE), Some(Move::Up));
        assert_eq!(action(KeyCode::Escape, false), Some(Action::Exit));
        assert_eq!(action(KeyCode::F1, false), Some(Action::TogglePanel));
        assert_eq!(action(KeyCode::F12, false), Some(Action::Screenshot));
        assert_eq!(action(KeyCode::BracketLeft, false), Some(Action::TimeBack));
        assert_eq!(
            action(KeyCode::BracketRight, false),
            Some(Action::TimeForward)
        );
        assert_eq!(action(KeyCode::KeyP, false), Some(Action::PlayClock));
        assert_eq!(action(KeyCode::KeyT, false), Some(Action::ToggleGi));
        assert_eq!(action(KeyCode::KeyV, false), Some(Action::NextView));
        assert_eq!(action(KeyCode::KeyV, true), Some(Action::FinalView));
        assert_eq!(action(KeyCode::Digit1, false), Some(Action::Camera(0)));
        assert_eq!(action(KeyCode::Digit9, true), Some(Action::Camera(8)));
        assert_eq!(action(KeyCode::Digit0, false), None);
        assert_eq!(action(KeyCode::KeyX, false), None);
    }

    #[test]
    fn movement_keys_do_nothing_else_and_the_table_names_every_binding() {
        for k in [
            KeyCode::KeyW,
            KeyCode::KeyA,
            KeyCode::KeyS,
            KeyCode::KeyD,
            KeyCode::KeyQ,
            KeyCode::KeyE,
        ] {
            assert_eq!(action(k, false), None, "{k:?}");
            assert_eq!(action(k, true), None, "{k:?}");
        }
        let keys: Vec<&str> = KEY_TABLE.iter().map(|(k, _)| *k).collect();
        for want in [
            "W / A / S / D",
            "Q / E",
            "[ / ]",
            "P",
            "T",
            "V",
            "F1",
            "F12",
            "Esc",
        ] {
            assert!(keys.contains(&want), "{want} missing from the key table");
        }
    }

    #[test]
    fn held_keys_give_axes_and_opposites_cancel() {
        let mut h = Held::default();
        assert_eq!(h.axes(), [0.0, 0.0, 0.0]);
        h.set(Move::Forward, true);
        h.set(Move::Left, true);
        assert_eq!(h.axes(), [-1.0, 0.0, 1.0]);
        h.set(Move::Back, true);
        h.set(Move::Up, true);
        assert_eq!(h.axes(), [-1.0, 1.0, 0.0]);
        h.set(Move::Back, false);
        h.clear();
        assert_eq!(h.axes(), [0.0, 0.0, 0.0]);
    }
}
