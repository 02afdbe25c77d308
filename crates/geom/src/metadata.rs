//! Node metadata: small ordered maps from text keys to [`MetaValue`]s (glTF `extras`,
//! GeoJSON properties).
//!
//! A city has one node per building and each carries a handful of entries, so the map is
//! a sorted vector rather than a tree, and keys and text values written as `&'static str`
//! literals ([`MetaValue::from_static`], [`Metadata::insert`] with a literal key) are
//! borrowed, not copied: a building's four entries cost one allocation. Entries inserted
//! in key order are appended without a search (writers that know their keys insert them
//! so).
//!
//! ```
//! use polis_geom::metadata::{MetaValue, Metadata};
//!
//! let mut m = Metadata::new();
//! m.insert("height", 12.5);
//! m.insert("kind", MetaValue::from_static("house"));
//! m.insert("floors", 4.0);
//! // Keys iterate in order, whatever the order of insertion.
//! let keys: Vec<&str> = m.keys().collect();
//! assert_eq!(keys, ["floors", "height", "kind"]);
//! assert_eq!(m.get("floors"), Some(&MetaValue::Number(4.0)));
//! assert_eq!(serde_json::to_string(&m).unwrap(), r#"{"floors":4.0,"height":12.5,"kind":"house"}"#);
//! ```

use std::borrow::Cow;

#[cfg(feature = "serde")]
use serde::de::{MapAccess, Visitor};
#[cfg(feature = "serde")]
use serde::ser::SerializeMap;
#[cfg(feature = "serde")]
use serde::{Deserialize, Deserializer, Serialize, Serializer};

/// A metadata value (exported as glTF `extras`, GeoJSON properties).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(untagged))]
pub enum MetaValue {
    /// Text, e.g. a building kind (borrowed when it is a `'static` literal).
    String(Cow<'static, str>),
    /// A finite number, e.g. a height in metres.
    Number(f64),
    /// A flag, e.g. "is a bridge".
    Bool(bool),
}

impl MetaValue {
    /// Text that lives for the whole program (a literal, a kind's name): kept by reference.
    pub const fn from_static(text: &'static str) -> Self {
        MetaValue::String(Cow::Borrowed(text))
    }

    /// The text, if the value is text.
    pub fn as_str(&self) -> Option<&str> {
        match self {
            MetaValue::String(s) => Some(s),
            _ => None,
        }
    }

    /// The number, if the value is a number.
    pub fn as_f64(&self) -> Option<f64> {
        match *self {
            MetaValue::Number(x) => Some(x),
            _ => None,
        }
    }
}

impl From<&str> for MetaValue {
    /// Copies the text (use [`MetaValue::from_static`] for literals to avoid the copy).
    fn from(s: &str) -> Self {
        MetaValue::String(Cow::Owned(s.to_owned()))
    }
}
impl From<String> for MetaValue {
    fn from(s: String) -> Self {
        MetaValue::String(Cow::Owned(s))
    }
}
impl From<Cow<'static, str>> for MetaValue {
    fn from(s: Cow<'static, str>) -> Self {
        MetaValue::String(s)
    }
}
impl From<f64> for MetaValue {
    fn from(x: f64) -> Self {
        MetaValue::Number(x)
    }
}
impl From<bool> for MetaValue {
    fn from(b: bool) -> Self {
        MetaValue::Bool(b)
    }
}

/// A node's metadata: entries in key order, each key at most once.
///
/// Serialised as a JSON-style map in key order (deterministic output); when a serialised
/// map repeats a key, the last value wins.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Metadata {
    /// Sorted by key, keys unique.
    entries: Vec<(Cow<'static, str>, MetaValue)>,
}

impl Metadata {
    /// No entries.
    pub const fn new() -> Self {
        Metadata {
            entries: Vec::new(),
        }
    }

    /// No entries, with room for `n` without reallocating.
    pub fn with_capacity(n: usize) -> Self {
        Metadata {
            entries: Vec::with_capacity(n),
        }
    }

    /// Number of entries.
    pub fn len(&self) -> usize {
        self.entries.len()
    }

    /// Whether there are no entries.
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    fn find(&self, key: &str) -> Result<usize, usize> {
        self.entries.binary_search_by(|(k, _)| (**k).cmp(key))
    }

    /// The value of `key`.
    pub fn get(&self, key: &str) -> Option<&MetaValue> {
        let i = self.find(key).ok()?;
        self.entries.get(i).map(|(_, v)| v)
    }

    /// Whether `key` has a value.
    pub fn contains_key(&self, key: &str) -> bool {
        self.find(key).is_ok()
    }

    /// Sets `key` to `value` and returns the value it replaces. A `&'static str` key is
    /// kept by reference.
    pub fn insert(
        &mut self,
        key: impl Into<Cow<'static, str>>,
        value: impl Into<MetaValue>,
    ) -> Option<MetaValue> {
        let key = key.into();
        let value = value.into();
        // Entries written in key order (a node's metadata usually is) are appended
        // without a search or a shift.
        if self.entries.last().is_none_or(|(last, _)| **last < *key) {
            self.entries.push((key, value));
            return None;
        }
        match self.find(&key) {
            Ok(i) => self
                .entries
                .get_mut(i)
                .map(|slot| std::mem::replace(&mut slot.1, value)),
            Err(i) => {
                self.entries.insert(i, (key, value));
                None
            }
        }
    }

    /// Removes `key` and returns its value.
    pub fn remove(&mut self, key: &str) -> Option<MetaValue> {
        let i = self.find(key).ok()?;
        Some(self.entries.remove(i).1)
    }

    /// Entries in key order.
    pub fn iter(&self) -> impl ExactSizeIterator<Item = (&str, &MetaValue)> + '_ {
        self.entries.iter().map(|(k, v)| (&**k, v))
    }

    /// Keys in order.
    pub fn keys(&self) -> impl ExactSizeIterator<Item = &str> + '_ {
        self.entries.iter().map(|(k, _)| &**k)
    }

    /// Values in key order.
    pub fn values(&self) -> impl ExactSizeIterator<Item = &MetaValue> + '_ {
        self.entries.iter().map(|(_, v)| v)
    }
}

impl<K: Into<Cow<'static, str>>, V: Into<MetaValue>> Extend<(K, V)> for Metadata {
    fn extend<I: IntoIterator<Item = (K, V)>>(&mut self, items: I) {
        for (k, v) in items {
            self.insert(k, v);
        }
    }
}

impl<K: Into<Cow<'static, str>>, V: Into<MetaValue>> FromIterator<(K, V)> for Metadata {
    fn from_iter<I: IntoIterator<Item = (K, V)>>(items: I) -> Self {
        let items = items.into_iter();
        let mut m = Metadata::with_capacity(items.size_hint().0);
        m.extend(items);
        m
    }
}

impl<K: Into<Cow<'static, str>>, V: Into<MetaValue>, const N: usize> From<[(K, V); N]>
    for Metadata
{
    fn from(items: [(K, V); N]) -> Self {
        items.into_iter().collect()
    }
}

impl<'a> IntoIterator for &'a Metadata {
    type Item = (&'a str, &'a MetaValue);
    type IntoIter = std::iter::Map<
        std::slice::Iter<'a, (Cow<'static, str>, MetaValue)>,
        fn(&'a (Cow<'static, str>, MetaValue)) -> (&'a str, &'a MetaValue),
    >;

    fn into_iter(self) -> Self::IntoIter {
        self.entries.iter().map(|(k, v)| (&**k, v))
    }
}

#[cfg(feature = "serde")]
impl Serialize for Metadata {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let mut map = serializer.serialize_map(Some(self.entries.len()))?;
        for (k, v) in &self.entries {
            map.serialize_entry(&**k, v)?;
        }
        map.end()
    }
}

#[cfg(feature = "serde")]
impl<'de> Deserialize<'de> for Metadata {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct MapVisitor;
        impl<'de> Visitor<'de> for MapVisitor {
            type Value = Metadata;
            fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str("a map from text keys to strings, numbers or booleans")
            }
            fn visit_map<A: MapAccess<'de>>(self, mut access: A) -> Result<Metadata, A::Error> {
                let mut m = Metadata::with_capacity(access.size_hint().unwrap_or(0).min(64));
                while let Some((k, v)) = access.next_entry::<String, MetaValue>()? {
                    m.insert(k, v);
                }
                Ok(m)
            }
        }
        deserializer.deserialize_map(MapVisitor)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn insert_replaces_and_keeps_order() {
        let mut m = Metadata::from([("b", 1.0), ("a", 2.0)]);
        assert_eq!(m.insert("b", 3.0), Some(MetaValue::Number(1.0)));
        assert_eq!(m.insert(String::from("c"), true), None);
        assert_eq!(
            m.iter().collect::<Vec<_>>(),
            [
                ("a", &MetaValue::Number(2.0)),
                ("b", &MetaValue::Number(3.0)),
                ("c", &MetaValue::Bool(true))
            ]
        );
        assert_eq!(m.remove("a"), Some(MetaValue::Number(2.0)));
        assert_eq!(m.remove("a"), None);
        assert!(!m.contains_key("a") && m.contains_key("c"));
        assert_eq!(m.len(), 2);
    }

    #[test]
    fn literals_are_borrowed_not_copied() {
        let mut m = Metadata::new();
        m.insert("kind", MetaValue::from_static("house"));
        let (k, v) = &m.entries[0];
        assert!(matches!(k, Cow::Borrowed(_)));
        assert!(matches!(v, MetaValue::String(Cow::Borrowed(_))));
        assert_eq!(m.get("kind").and_then(MetaValue::as_str), Some("house"));
    }

    #[test]
    fn a_repeated_key_in_json_keeps_the_last_value() {
        let m: Metadata = serde_json::from_str(r#"{"k": 1, "a": "x", "k": 2}"#).unwrap();
        assert_eq!(m.keys().collect::<Vec<_>>(), ["a", "k"]);
        assert_eq!(m.get("k").and_then(MetaValue::as_f64), Some(2.0));
        assert!(serde_json::from_str::<Metadata>(r#"{"k": [1]}"#).is_err());
        assert!(serde_json::from_str::<Metadata>("[1]").is_err());
    }

    fn value() -> impl Strategy<Value = MetaValue> {
        prop_oneof![
            "[a-z]{0,4}".prop_map(MetaValue::from),
            (-1e6..1e6f64).prop_map(MetaValue::from),
            any::<bool>().prop_map(MetaValue::from),
        ]
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(128))]

        /// Behaves as an ordered map (a `BTreeMap` as reference) under any inserts and
        /// removals, and survives a JSON round trip.
        #[test]
        fn matches_an_ordered_map(ops in prop::collection::vec(("[a-d]{1,2}", prop::option::of(value())), 0..40)) {
            let mut m = Metadata::new();
            let mut reference = std::collections::BTreeMap::new();
            for (k, v) in ops {
                match v {
                    Some(v) => prop_assert_eq!(m.insert(k.clone(), v.clone()), reference.insert(k, v)),
                    None => prop_assert_eq!(m.remove(&k), reference.remove(&k)),
                }
            }
            prop_assert_eq!(m.len(), reference.len());
            for ((k, v), (rk, rv)) in m.iter().zip(&reference) {
                prop_assert_eq!(k, rk.as_str());
                prop_assert_eq!(v, rv);
            }
            let json = serde_json::to_string(&m).unwrap();
            prop_assert_eq!(&json, &serde_json::to_string(&reference).unwrap());
            let back: Metadata = serde_json::from_str(&json).unwrap();
            prop_assert_eq!(back, m);
        }
    }
}
