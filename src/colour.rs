//! Colours: [`Rgba`] and the default palette that colour indices choose
//! from. The drawing, the shape grammar and the renderers share them
//! (`render` re-exports both); this module uses nothing of the crate.

/// An RGBA colour.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Rgba(pub u8, pub u8, pub u8, pub u8);

impl Rgba {
    /// `white`, `black`, `none`/`transparent`, `#rgb`, `#rrggbb` or `#rrggbbaa`.
    pub fn parse(s: &str) -> Option<Rgba> {
        let named = match s.to_ascii_lowercase().as_str() {
            "white" => Some(Rgba(255, 255, 255, 255)),
            "black" => Some(Rgba(0, 0, 0, 255)),
            "none" | "transparent" => Some(Rgba(0, 0, 0, 0)),
            "gray" | "grey" => Some(Rgba(128, 128, 128, 255)),
            _ => None,
        };
        if named.is_some() {
            return named;
        }
        let hex = s.strip_prefix('#')?;
        let digit = |i: usize, len: usize| u8::from_str_radix(hex.get(i..i + len)?, 16).ok();
        match hex.len() {
            3 => Some(Rgba(
                digit(0, 1)? * 17,
                digit(1, 1)? * 17,
                digit(2, 1)? * 17,
                255,
            )),
            6 => Some(Rgba(digit(0, 2)?, digit(2, 2)?, digit(4, 2)?, 255)),
            8 => Some(Rgba(digit(0, 2)?, digit(2, 2)?, digit(4, 2)?, digit(6, 2)?)),
            _ => None,
        }
    }

    pub fn hex(self) -> String {
        format!("#{:02x}{:02x}{:02x}", self.0, self.1, self.2)
    }
}

/// The default colour map for a white page: index 1 is near-black, then a
/// run of distinct colours; indices wrap around.
const PALETTE: [Rgba; 12] = [
    Rgba(64, 64, 64, 255),
    Rgba(24, 24, 24, 255),
    Rgba(214, 39, 40, 255),
    Rgba(31, 119, 180, 255),
    Rgba(44, 160, 44, 255),
    Rgba(255, 127, 14, 255),
    Rgba(148, 103, 189, 255),
    Rgba(140, 86, 75, 255),
    Rgba(227, 119, 194, 255),
    Rgba(127, 127, 127, 255),
    Rgba(188, 189, 34, 255),
    Rgba(23, 190, 207, 255),
];

/// The colour of index `i` in the default map.
pub fn palette(i: i64) -> Rgba {
    PALETTE[i.rem_euclid(PALETTE.len() as i64) as usize]
}
