//! The `/log` channel's share of `tracing`: every event the library emits at debug level
//! or above while a recorded run is on its thread (the loop's safe stops and recoveries,
//! the colour model's switches, the sequencer's and arbiters' changes of mind), kept for
//! the recording, as the `tracing` crate's own subscribers keep them for a terminal.
//!
//! [`Capture`] is a `tracing` subscriber that wraps the one that was current on the
//! thread: what that one would have printed it still prints, and the recording gets its
//! own copy of every event at [`CAPTURED`] or above, whatever the terminal's filter. The
//! recorder sets it as the thread's default for the run ([`Capture::install`]) and, each
//! tick, writes what was captured at that tick's time. Per-frame `trace` events stay out:
//! they would dominate the file and the cost of recording.

use std::fmt::Write as _;
use std::sync::{Arc, Mutex};
use tracing::field::{Field, Visit};
use tracing::level_filters::LevelFilter;
use tracing::subscriber::Interest;
use tracing::{Dispatch, Event, Level, Metadata, Subscriber, span};

/// The least severe level recorded.
pub const CAPTURED: Level = Level::DEBUG;

/// One captured event.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Captured {
    /// `foxglove.Log` level: 1 debug (and trace), 2 info, 3 warning, 4 error.
    pub level: u8,
    /// The event's target (`marsupial::loop` …), Foxglove's logger name.
    pub target: String,
    /// The message, then each field as ` name=value`.
    pub message: String,
}

/// Events captured and not yet written, shared between the subscriber and the recorder.
pub type Captures = Arc<Mutex<Vec<Captured>>>;

/// A subscriber that copies events at [`CAPTURED`] or above into [`Captures`] and hands
/// everything to the subscriber that was current when it was made.
pub struct Capture {
    inner: Dispatch,
    out: Captures,
    hint: LevelFilter,
}

impl Capture {
    /// Wraps the thread's current subscriber, capturing into `out`.
    pub fn new(out: Captures) -> Self {
        let inner = tracing::dispatcher::get_default(Dispatch::clone);
        Self {
            inner,
            out,
            // The global bound already covers the wrapped subscriber.
            hint: LevelFilter::current().max(LevelFilter::from_level(CAPTURED)),
        }
    }

    /// Makes a capture into `out` the thread's subscriber until the guard drops.
    pub fn install(out: Captures) -> tracing::dispatcher::DefaultGuard {
        tracing::dispatcher::set_default(&Dispatch::new(Self::new(out)))
    }

    fn wanted(meta: &Metadata<'_>) -> bool {
        meta.is_event() && *meta.level() <= CAPTURED
    }
}

impl Subscriber for Capture {
    fn register_callsite(&self, meta: &'static Metadata<'static>) -> Interest {
        let inner = self.inner.register_callsite(meta);
        if Self::wanted(meta) && !inner.is_always() {
            Interest::sometimes()
        } else {
            inner
        }
    }

    fn enabled(&self, meta: &Metadata<'_>) -> bool {
        Self::wanted(meta) || self.inner.enabled(meta)
    }

    fn max_level_hint(&self) -> Option<LevelFilter> {
        Some(self.hint)
    }

    fn new_span(&self, span: &span::Attributes<'_>) -> span::Id {
        self.inner.new_span(span)
    }

    fn record(&self, span: &span::Id, values: &span::Record<'_>) {
        self.inner.record(span, values);
    }

    fn record_follows_from(&self, span: &span::Id, follows: &span::Id) {
        self.inner.record_follows_from(span, follows);
    }

    fn event(&self, event: &Event<'_>) {
        let meta = event.metadata();
        if Self::wanted(meta) {
            let mut text = Text::default();
            event.record(&mut text);
            let level = match *meta.level() {
                Level::ERROR => 4,
                Level::WARN => 3,
                Level::INFO => 2,
                _ => 1,
            };
            let captured = Captured {
                level,
                target: meta.target().to_owned(),
                message: text.message + &text.fields,
            };
            self.out.lock().unwrap_or_else(|e| e.into_inner()).push(captured);
        }
        if self.inner.enabled(meta) {
            self.inner.event(event);
        }
    }

    fn enter(&self, span: &span::Id) {
        self.inner.enter(span);
    }

    fn exit(&self, span: &span::Id) {
        self.inner.exit(span);
    }

    fn clone_span(&self, id: &span::Id) -> span::Id {
        self.inner.clone_span(id)
    }

    fn try_close(&self, id: span::Id) -> bool {
        self.inner.try_close(id)
    }
}

/// An event's message and its other fields as ` name=value`, in the order written.
#[derive(Default)]
struct Text {
    message: String,
    fields: String,
}

impl Visit for Text {
    fn record_debug(&mut self, field: &Field, value: &dyn std::fmt::Debug) {
        if field.name() == "message" {
            let _ = write!(self.message, "{value:?}");
        } else {
            let _ = write!(self.fields, " {}={value:?}", field.name());
        }
    }

    fn record_str(&mut self, field: &Field, value: &str) {
        if field.name() == "message" {
            self.message.push_str(value);
        } else {
            let _ = write!(self.fields, " {}={value}", field.name());
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn drain(out: &Captures) -> Vec<Captured> {
        std::mem::take(&mut *out.lock().unwrap())
    }

    #[test]
    fn events_at_debug_and_above_are_captured_with_their_fields_and_nothing_else() {
        let out = Captures::default();
        {
            let _guard = Capture::install(out.clone());
            tracing::trace!(target: "marsupial::sim", t = 1.0, "per-frame");
            tracing::debug!(target: "marsupial::arbiter", winner = "approach", "changed");
            tracing::info!(target: "marsupial::perception", from = %"rgb", to = %"sct", "colour statistics switched");
            tracing::warn!(target: "marsupial::loop", now = 2.5, reason = %"camera stale", "safe stop");
            tracing::error!("plain");
            let _span = tracing::info_span!("a span").entered();
        }
        let got = drain(&out);
        let lines: Vec<(u8, &str, &str)> = got
            .iter()
            .map(|c| (c.level, c.target.as_str(), c.message.as_str()))
            .collect();
        assert_eq!(
            lines,
            [
                (1, "marsupial::arbiter", "changed winner=approach"),
                (2, "marsupial::perception", "colour statistics switched from=rgb to=sct"),
                (3, "marsupial::loop", "safe stop now=2.5 reason=camera stale"),
                (4, module_path!(), "plain"),
            ]
        );
        // The guard restored the thread's subscriber: nothing is captured any more.
        tracing::warn!("after");
        assert!(drain(&out).is_empty());
    }

    #[test]
    fn the_wrapped_subscriber_still_sees_what_it_asked_for() {
        use std::sync::atomic::{AtomicUsize, Ordering};
        /// Counts the events it is given, enabling warnings and above only.
        struct Counter(Arc<AtomicUsize>);
        impl Subscriber for Counter {
            fn enabled(&self, meta: &Metadata<'_>) -> bool {
                *meta.level() <= Level::WARN
            }
            fn new_span(&self, _: &span::Attributes<'_>) -> span::Id {
                span::Id::from_u64(1)
            }
            fn record(&self, _: &span::Id, _: &span::Record<'_>) {}
            fn record_follows_from(&self, _: &span::Id, _: &span::Id) {}
            fn event(&self, _: &Event<'_>) {
                self.0.fetch_add(1, Ordering::Relaxed);
            }
            fn enter(&self, _: &span::Id) {}
            fn exit(&self, _: &span::Id) {}
        }
        let seen = Arc::new(AtomicUsize::new(0));
        let outer = Dispatch::new(Counter(seen.clone()));
        let out = Captures::default();
        tracing::dispatcher::with_default(&outer, || {
            let _guard = Capture::install(out.clone());
            tracing::debug!("kept for the log only");
            tracing::warn!("both");
        });
        assert_eq!(seen.load(Ordering::Relaxed), 1);
        assert_eq!(drain(&out).len(), 2);
    }
}
