//! What the editor features ask the Haas lathe dialect.

use nc_exec::haas_lathe::lower::HaasBlock;

/// What I and K mean in an arc block: the centre from the start point, I
/// along X as a radius, K along Z (lathe manual §5.8 (001:611-613)).
pub(crate) fn arc_centre(block: &HaasBlock) -> Vec<(u8, String)> {
    if !block.has_code(b'G', 2) && !block.has_code(b'G', 3) {
        return Vec::new();
    }
    vec![
        (b'I', "Arc centre along X from the start point, as a radius (not a diameter)".to_owned()),
        (b'K', "Arc centre along Z from the start point".to_owned()),
    ]
}
