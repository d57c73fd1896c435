//! Case-file JSON read with every repeated key refused (serde_json keeps the last of them).

use serde_json::Value;

/// Parse JSON text into a [`Value`], refusing a key repeated within one object anywhere in the
/// document (`bodies[0]: duplicate key "length"`).
pub fn parse_unique_keys(text: &str) -> Result<Value, serde_json::Error> {
    use serde::de::DeserializeSeed;
    let mut de = serde_json::Deserializer::from_str(text);
    let v = UniqueKeys(String::new()).deserialize(&mut de)?;
    de.end()?;
    Ok(v)
}

/// Builds a [`Value`] like serde_json's own deserializer but errors on a repeated object key.
/// Hand-written because serde_json silently keeps the last of repeated keys and has no option to
/// refuse them (and `Value`'s own `Deserialize` builds its map the same way). The field is the
/// path of the value being read, in the messages' `bodies[0].section` style.
struct UniqueKeys(String);

impl<'de> serde::de::DeserializeSeed<'de> for UniqueKeys {
    type Value = Value;
    fn deserialize<D: serde::Deserializer<'de>>(self, d: D) -> Result<Value, D::Error> {
        d.deserialize_any(self)
    }
}

impl<'de> serde::de::Visitor<'de> for UniqueKeys {
    type Value = Value;
    fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("a JSON value")
    }
    fn visit_bool<E>(self, v: bool) -> Result<Value, E> {
        Ok(Value::Bool(v))
    }
    fn visit_i64<E>(self, v: i64) -> Result<Value, E> {
        Ok(v.into())
    }
    fn visit_u64<E>(self, v: u64) -> Result<Value, E> {
        Ok(v.into())
    }
    fn visit_f64<E>(self, v: f64) -> Result<Value, E> {
        Ok(v.into())
    }
    fn visit_str<E>(self, v: &str) -> Result<Value, E> {
        Ok(Value::String(v.to_owned()))
    }
    fn visit_string<E>(self, v: String) -> Result<Value, E> {
        Ok(Value::String(v))
    }
    fn visit_unit<E>(self) -> Result<Value, E> {
        Ok(Value::Null)
    }
    fn visit_none<E>(self) -> Result<Value, E> {
        Ok(Value::Null)
    }
    fn visit_some<D: serde::Deserializer<'de>>(self, d: D) -> Result<Value, D::Error> {
        serde::de::DeserializeSeed::deserialize(self, d)
    }
    fn visit_seq<A: serde::de::SeqAccess<'de>>(self, mut seq: A) -> Result<Value, A::Error> {
        let mut v = Vec::new();
        while let Some(x) = seq.next_element_seed(UniqueKeys(format!("{}[{}]", self.0, v.len())))? {
            v.push(x);
        }
        Ok(Value::Array(v))
    }
    fn visit_map<A: serde::de::MapAccess<'de>>(self, mut map: A) -> Result<Value, A::Error> {
        let mut m = serde_json::Map::new();
        while let Some(k) = map.next_key::<String>()? {
            if m.contains_key(&k) {
                let at = if self.0.is_empty() { String::new() } else { format!("{}: ", self.0) };
                return Err(serde::de::Error::custom(format!("{at}duplicate key \"{k}\"")));
            }
            let path = if self.0.is_empty() { k.clone() } else { format!("{}.{k}", self.0) };
            let v = map.next_value_seed(UniqueKeys(path))?;
            m.insert(k, v);
        }
        Ok(Value::Object(m))
    }
}
