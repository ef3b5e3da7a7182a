//! The Haas lathe's offset pages as a machine's configuration gives them:
//! the work offsets by their G code, and the tool offsets that `Txxyy`
//! selects by `yy`, with their nose radius and tip code (lathe manual §7
//! (001:825-826, 879-951, 126-131, 233-277)).

use crate::machine::ToolEntry;

/// The G code of the work offset `name` (`G54`–`G59`, `G110`–`G129`).
pub fn work_offset_code(name: &str) -> Option<u8> {
    let code = name.strip_prefix(['G', 'g'])?.parse().ok()?;
    matches!(code, 54..=59 | 110..=129).then_some(code)
}

/// The number of the tool offset `name`, 1–99.
pub fn tool_offset_number(name: &str) -> Option<u8> {
    name.parse().ok().filter(|number| (1..=99).contains(number))
}

/// A tool offset of nose radius `radius` (µm, not negative) and tip code
/// `tip` (0–9); why not when they are out of range.
pub fn tool_offset(radius: i32, tip: Option<u8>) -> Result<ToolEntry, String> {
    if radius < 0 {
        return Err("the nose radius must not be negative".to_owned());
    }
    if tip.is_some_and(|tip| tip > 9) {
        return Err("the tip code is 0 to 9".to_owned());
    }
    Ok(ToolEntry { radius, lengths: [0; 6], tip })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_and_values_of_the_offset_pages() {
        assert_eq!(
            [work_offset_code("G54"), work_offset_code("g129"), work_offset_code("G53")],
            [Some(54), Some(129), None]
        );
        assert_eq!([work_offset_code("G60"), work_offset_code("G109"), work_offset_code("54")], [None; 3]);
        assert_eq!(
            [tool_offset_number("1"), tool_offset_number("99"), tool_offset_number("0")],
            [Some(1), Some(99), None]
        );
        assert_eq!(tool_offset(800, Some(3)), Ok(ToolEntry { radius: 800, lengths: [0; 6], tip: Some(3) }));
        assert!(tool_offset(-1, None).is_err() && tool_offset(0, Some(10)).is_err());
    }
}
