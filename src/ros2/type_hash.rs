//! ROS 2 type hashes (RIHS01, REP-2011, as `rosidl_generator_type_description` computes
//! them), from type descriptions.
//!
//! `rmw_zenoh` puts each topic's and service's type hash in its key expression, so a
//! publisher and a subscriber meet only when their hashes agree. The hash is the SHA-256
//! of a JSON text: the type's description (its name, and per field the name, type id,
//! capacity, string capacity and nested type name) followed by the descriptions of every
//! type it references, sorted by name, written as Python's `json.dumps` writes them
//! with the separators `", "` and `": "` (`rosidl_generator_type_description`). Default
//! values are not part of it. A service's description has three fields, its request,
//! response and event messages, and the event message references
//! `service_msgs/msg/ServiceEventInfo` and `builtin_interfaces/msg/Time`.
//!
//! The tests check the result against hashes `rmw_zenoh`'s design document and ROS 2
//! installations print: `std_msgs/msg/String`, `geometry_msgs/msg/Twist` and the service
//! `example_interfaces/srv/AddTwoInts`.

use sha2::{Digest, Sha256};
use std::fmt::Write as _;

/// A field's type, as `type_description_interfaces/msg/FieldType` numbers it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum FieldType {
    /// A nested message, by full name (`geometry_msgs/msg/Vector3`).
    Nested(String),
    /// `bool`.
    Bool,
    /// `uint8` (and `char`, which ROS 2 messages map to `uint8`).
    U8,
    /// `int8`.
    I8,
    /// `uint16`.
    U16,
    /// `int32`.
    I32,
    /// `uint32`.
    U32,
    /// `int64`.
    I64,
    /// `float32`.
    F32,
    /// `float64`.
    F64,
    /// An unbounded `string`.
    String,
    /// A fixed-size array of a basic or nested type (`uint8[16]`, `float64[36]`).
    Array(Box<FieldType>, u64),
    /// An unbounded sequence (`uint8[]`).
    Sequence(Box<FieldType>),
    /// A bounded sequence (`Request[<=1]`).
    BoundedSequence(Box<FieldType>, u64),
}

impl FieldType {
    /// A nested message.
    pub fn nested(name: impl Into<String>) -> Self {
        FieldType::Nested(name.into())
    }

    /// A fixed-size array of `n` elements.
    pub fn array(element: FieldType, n: u64) -> Self {
        FieldType::Array(Box::new(element), n)
    }

    /// An unbounded sequence.
    pub fn sequence(element: FieldType) -> Self {
        FieldType::Sequence(Box::new(element))
    }

    /// The element's id before any array/sequence offset is added.
    fn base_id(&self) -> u32 {
        match self {
            FieldType::Nested(_) => 1,
            FieldType::I8 => 2,
            FieldType::U8 => 3,
            FieldType::U16 => 5,
            FieldType::I32 => 6,
            FieldType::U32 => 7,
            FieldType::I64 => 8,
            FieldType::F32 => 10,
            FieldType::F64 => 11,
            FieldType::Bool => 15,
            FieldType::String => 17,
            FieldType::Array(t, _) | FieldType::Sequence(t) | FieldType::BoundedSequence(t, _) => t.base_id(),
        }
    }

    /// `(type_id, capacity, nested_type_name)` as the description writes them.
    fn parts(&self) -> (u32, u64, &str) {
        fn nested(t: &FieldType) -> &str {
            match t {
                FieldType::Nested(n) => n,
                _ => "",
            }
        }
        match self {
            FieldType::Array(t, n) => (t.base_id() + 48, *n, nested(t)),
            FieldType::BoundedSequence(t, n) => (t.base_id() + 96, *n, nested(t)),
            FieldType::Sequence(t) => (t.base_id() + 144, 0, nested(t)),
            t => (t.base_id(), 0, nested(t)),
        }
    }
}

/// One field of a message.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Field {
    /// Its name.
    pub name: &'static str,
    /// Its type.
    pub ty: FieldType,
}

/// `Field { name, ty }`, shorter.
pub fn field(name: &'static str, ty: FieldType) -> Field {
    Field { name, ty }
}

/// One message's description: its full name and its fields in order.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TypeDescription {
    /// `package/msg/Name`, `package/srv/Name_Request`, `package/action/Name_Goal` ….
    pub name: String,
    /// Its fields.
    pub fields: Vec<Field>,
}

impl TypeDescription {
    /// A description.
    pub fn new(name: impl Into<String>, fields: Vec<Field>) -> Self {
        Self {
            name: name.into(),
            fields,
        }
    }

    fn write_json(&self, out: &mut String) {
        let _ = write!(out, "{{\"type_name\": \"{}\", \"fields\": [", self.name);
        for (i, f) in self.fields.iter().enumerate() {
            let (id, capacity, nested) = f.ty.parts();
            if i > 0 {
                out.push_str(", ");
            }
            let _ = write!(
                out,
                "{{\"name\": \"{}\", \"type\": {{\"type_id\": {id}, \"capacity\": {capacity}, \"string_capacity\": 0, \"nested_type_name\": \"{nested}\"}}}}",
                f.name
            );
        }
        out.push_str("]}");
    }
}

/// The hash `RIHS01_<64 hex>` of `top`, which references the types in `library` (it may
/// hold more; only those `top` reaches, directly or through each other, are hashed).
///
/// # Panics
/// Never for a `library` that holds every type `top` reaches; a missing one is a bug in
/// the crate's own tables, caught by the tests that hash every interface it uses.
pub fn type_hash(top: &TypeDescription, library: &[TypeDescription]) -> String {
    let mut reached: Vec<&TypeDescription> = Vec::new();
    let mut queue: Vec<&str> = nested_names(top).collect();
    while let Some(name) = queue.pop() {
        if reached.iter().any(|t| t.name == name) {
            continue;
        }
        let Some(t) = library.iter().find(|t| t.name == name) else {
            panic!("type `{name}` referenced by `{}` is not described", top.name);
        };
        reached.push(t);
        queue.extend(nested_names(t));
    }
    reached.sort_by(|a, b| a.name.cmp(&b.name));
    let mut json = String::from("{\"type_description\": ");
    top.write_json(&mut json);
    json.push_str(", \"referenced_type_descriptions\": [");
    for (i, t) in reached.iter().enumerate() {
        if i > 0 {
            json.push_str(", ");
        }
        t.write_json(&mut json);
    }
    json.push_str("]}");
    let digest = Sha256::digest(json.as_bytes());
    let mut out = String::with_capacity(7 + 64);
    out.push_str("RIHS01_");
    for b in digest {
        let _ = write!(out, "{b:02x}");
    }
    out
}

fn nested_names(t: &TypeDescription) -> impl Iterator<Item = &str> + '_ {
    t.fields.iter().filter_map(|f| match f.ty.parts().2 {
        "" => None,
        n => Some(n),
    })
}

/// `builtin_interfaces/msg/Time`.
pub fn time() -> TypeDescription {
    TypeDescription::new(
        "builtin_interfaces/msg/Time",
        vec![field("sec", FieldType::I32), field("nanosec", FieldType::U32)],
    )
}

/// `service_msgs/msg/ServiceEventInfo` (its `char[16] client_gid` is `uint8[16]`).
pub fn service_event_info() -> TypeDescription {
    TypeDescription::new(
        "service_msgs/msg/ServiceEventInfo",
        vec![
            field("event_type", FieldType::U8),
            field("stamp", FieldType::nested("builtin_interfaces/msg/Time")),
            field("client_gid", FieldType::array(FieldType::U8, 16)),
            field("sequence_number", FieldType::I64),
        ],
    )
}

/// The hash of the service `name` (`package/srv/Name`, or an action's
/// `package/action/Name_SendGoal`), whose request and response are `request` and
/// `response` (named `<name>_Request` and `<name>_Response`) and whose other referenced
/// types are in `library`.
pub fn service_hash(name: &str, request: Vec<Field>, response: Vec<Field>, library: &[TypeDescription]) -> String {
    let (req, res, ev) = (
        format!("{name}_Request"),
        format!("{name}_Response"),
        format!("{name}_Event"),
    );
    let top = TypeDescription::new(
        name,
        vec![
            field("request_message", FieldType::nested(&req)),
            field("response_message", FieldType::nested(&res)),
            field("event_message", FieldType::nested(&ev)),
        ],
    );
    let event = vec![
        field("info", FieldType::nested("service_msgs/msg/ServiceEventInfo")),
        field(
            "request",
            FieldType::BoundedSequence(Box::new(FieldType::nested(&req)), 1),
        ),
        field(
            "response",
            FieldType::BoundedSequence(Box::new(FieldType::nested(&res)), 1),
        ),
    ];
    let mut lib = library.to_vec();
    lib.push(TypeDescription::new(req, request));
    lib.push(TypeDescription::new(res, response));
    lib.push(TypeDescription::new(ev, event));
    lib.push(time());
    lib.push(service_event_info());
    type_hash(&top, &lib)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn vector3() -> TypeDescription {
        TypeDescription::new(
            "geometry_msgs/msg/Vector3",
            vec![
                field("x", FieldType::F64),
                field("y", FieldType::F64),
                field("z", FieldType::F64),
            ],
        )
    }

    #[test]
    fn std_msgs_string_hashes_as_ros_2_prints_it() {
        let s = TypeDescription::new("std_msgs/msg/String", vec![field("data", FieldType::String)]);
        assert_eq!(
            type_hash(&s, &[]),
            "RIHS01_df668c740482bbd48fb39d76a70dfd4bd59db1288021743503259e948f6b1a18"
        );
    }

    #[test]
    fn twist_hashes_as_ros_2_prints_it() {
        let v = || FieldType::nested("geometry_msgs/msg/Vector3");
        let twist = TypeDescription::new(
            "geometry_msgs/msg/Twist",
            vec![field("linear", v()), field("angular", v())],
        );
        assert_eq!(
            type_hash(&twist, &[vector3()]),
            "RIHS01_9c45bf16fe0983d80e3cfe750d6835843d265a9a6c46bd2e609fcddde6fb8d2a"
        );
    }

    #[test]
    fn a_service_hashes_as_ros_2_prints_it() {
        let h = service_hash(
            "example_interfaces/srv/AddTwoInts",
            vec![field("a", FieldType::I64), field("b", FieldType::I64)],
            vec![field("sum", FieldType::I64)],
            &[],
        );
        assert_eq!(
            h,
            "RIHS01_e118de6bf5eeb66a2491b5bda11202e7b68f198d6f67922cf30364858239c81a"
        );
    }

    #[test]
    fn the_hash_changes_with_any_field() {
        let a = TypeDescription::new("p/msg/A", vec![field("x", FieldType::F64)]);
        let b = TypeDescription::new("p/msg/A", vec![field("x", FieldType::F32)]);
        let c = TypeDescription::new("p/msg/A", vec![field("y", FieldType::F64)]);
        let (ha, hb, hc) = (type_hash(&a, &[]), type_hash(&b, &[]), type_hash(&c, &[]));
        assert!(ha != hb && ha != hc && hb != hc);
        assert_eq!(ha.len(), 7 + 64);
    }
}
