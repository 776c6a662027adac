//! Arbiter decisions reach `tracing`. In its own test binary: tracing caches per-callsite
//! interest process-wide, so a test running without a subscriber in parallel could hide
//! these events.

use marsupial::arbiter::Priority;
use marsupial::schemas::{Behavior, Feedback, Inputs, MotorOutput, Step};

struct Fixed(&'static str, f64, f64, MotorOutput);
impl Behavior for Fixed {
    fn name(&self) -> &str {
        self.0
    }
    fn tick(&mut self, _mem: &mut (), inputs: &Inputs<'_>) -> Option<Step> {
        (inputs.now >= self.1 && inputs.now < self.2).then(|| Step::running(self.3, Feedback::new("fixed", inputs.now)))
    }
}

#[test]
fn decisions_are_traced() {
    use std::io::Write;
    use std::sync::{Arc, Mutex};
    #[derive(Clone, Default)]
    struct Buf(Arc<Mutex<Vec<u8>>>);
    impl Write for Buf {
        fn write(&mut self, b: &[u8]) -> std::io::Result<usize> {
            self.0.lock().unwrap().extend_from_slice(b);
            Ok(b.len())
        }
        fn flush(&mut self) -> std::io::Result<()> {
            Ok(())
        }
    }
    let buf = Buf::default();
    let b2 = buf.clone();
    let subscriber = tracing_subscriber::fmt()
        .with_max_level(tracing::Level::DEBUG)
        .with_ansi(false)
        .with_writer(move || b2.clone())
        .finish();
    tracing::subscriber::with_default(subscriber, || {
        let hi = Fixed("avoid", 5.0, 10.0, MotorOutput::twist(0.0, 1.0));
        let lo = Fixed("approach", 0.0, 100.0, MotorOutput::twist(0.1, 0.0));
        let mut p = Priority::new("root", vec![Box::new(hi), Box::new(lo)]);
        p.tick(&mut (), &Inputs::empty(6.0));
    });
    let text = String::from_utf8(buf.0.lock().unwrap().clone()).unwrap();
    assert!(text.contains("decision"), "{text}");
    assert!(text.contains("arbiter=\"root\""), "{text}");
    assert!(text.contains("active=[\"avoid\", \"approach\"]"), "{text}");
    assert!(text.contains("winner=\"avoid\""), "{text}");
    assert!(text.contains("approach=Twist"), "{text}");
}
