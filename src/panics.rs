//! Containing panics raised inside code the crate does not own (device drivers, file
//! decoders), so that a broken driver or a malformed file becomes a typed error or a safe
//! stop, never a crashed robot.

use std::panic::{AssertUnwindSafe, catch_unwind};

/// Runs `f`, turning a panic inside it into the panic's message (`fallback` when the
/// payload is not a string).
///
/// The closure is treated as unwind-safe: callers use it only where the state a panic
/// could leave half-updated is dropped or replaced afterwards (a decoder's output, a
/// driver call's result).
pub(crate) fn contain<R>(fallback: &str, f: impl FnOnce() -> R) -> Result<R, String> {
    catch_unwind(AssertUnwindSafe(f)).map_err(|payload| {
        payload
            .downcast_ref::<&str>()
            .map(|s| (*s).to_owned())
            .or_else(|| payload.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| fallback.to_owned())
    })
}

#[cfg(test)]
mod tests {
    use super::contain;

    #[test]
    fn a_panic_becomes_its_message() {
        assert_eq!(contain("none", || 3), Ok(3));
        assert_eq!(contain("none", || panic!("static")), Err::<(), _>("static".into()));
        let n = 7;
        assert_eq!(
            contain("none", || panic!("formatted {n}")),
            Err::<(), _>("formatted 7".into())
        );
        assert_eq!(
            contain("none", || std::panic::panic_any(42u8)),
            Err::<(), _>("none".into())
        );
    }
}
