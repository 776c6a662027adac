//! A transient-local publisher, as `rmw_zenoh` makes one: the publisher and a cache of
//! its last `depth` messages that a late subscriber queries.
//!
//! `rmw_zenoh` declares a publication cache beside a transient-local publisher, listening
//! on `<session id>/<topic key>` (its `queryable_prefix` is the session id as tokens
//! write it) and answering with the cached samples on the topic's own key; a
//! transient-local subscriber queries `*/<topic key>` when it starts, accepting replies
//! on any key, and `<session id>/<topic key>` when a new publisher's token appears
//! (`rmw_publisher_data.cpp`, `rmw_subscription_data.cpp`). The bridge's one
//! transient-local topic is each action's `status`, depth 1, so the cache holds the last
//! message and its attachment.

use super::keys::{Attachment, RmwPublisher};
use std::sync::{Arc, Mutex};
use zenoh::Wait;
use zenoh::query::Queryable;

/// The last message, with the attachment it was sent with.
type Last = Arc<Mutex<Option<(Vec<u8>, [u8; 33])>>>;

/// A publisher whose last message a late subscriber still gets.
pub struct LatchedPublisher {
    publisher: RmwPublisher,
    last: Last,
    _cache: Queryable<()>,
}

impl LatchedPublisher {
    /// Wraps `publisher` and declares its cache on `session`, under `zid` (the session id
    /// as [`super::keys::zid_string`] writes it).
    ///
    /// # Errors
    /// Zenoh's, as text.
    pub fn new(session: &zenoh::Session, publisher: RmwPublisher, zid: &str) -> Result<Self, String> {
        let key = publisher.key();
        let last: Last = Arc::new(Mutex::new(None));
        let held = last.clone();
        let topic = key.clone();
        let cache = session
            .declare_queryable(format!("{zid}/{key}"))
            .complete(true)
            .callback(move |query| {
                let Some((payload, att)) = held.lock().ok().and_then(|l| l.clone()) else {
                    return;
                };
                // A query that accepts only its own key (not `rmw_zenoh`'s) gets no reply:
                // Zenoh refuses a reply on another key, and the sample's key is the topic's.
                let _ = query.reply(topic.clone(), payload).attachment(att.to_vec()).wait();
            })
            .wait()
            .map_err(|e| e.to_string())?;
        Ok(Self {
            publisher,
            last,
            _cache: cache,
        })
    }

    /// Publishes `payload` and keeps it for late subscribers.
    ///
    /// # Errors
    /// Zenoh's, as text (the message is kept even then).
    pub fn put(&self, payload: &[u8]) -> Result<(), String> {
        let att: Attachment = self.publisher.next_attachment();
        if let Ok(mut l) = self.last.lock() {
            *l = Some((payload.to_vec(), att.encode()));
        }
        self.publisher.put_with(payload, &att)
    }

    /// The topic's key.
    pub fn key(&self) -> String {
        self.publisher.key()
    }
}
