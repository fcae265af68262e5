//! A glTF primitive's positions as floats, whatever `KHR_mesh_quantization` stored them as:
//! our own tiles store shorts on a grid their node's transform undoes (see
//! `output::gltf::quantize`), gltfpack stores shorts or bytes, others floats. The gltf
//! crate's reader takes every position for a float; this reads each type as itself.

/// A primitive's positions as floats: floats as they are, integers (`KHR_mesh_quantization`)
/// as their values, or divided by their type's largest when normalized; `None` when it has
/// none or they cannot be read.
pub fn positions<'a>(
    prim: &gltf::Primitive<'a>,
    get: impl Fn(gltf::Buffer<'a>) -> Option<&'a [u8]> + Clone,
) -> Option<Vec<[f32; 3]>> {
    use gltf::accessor::{DataType, Iter};
    let a = prim.get(&gltf::Semantic::Positions)?;
    if a.dimensions() != gltf::accessor::Dimensions::Vec3 {
        return None;
    }
    let norm = |largest: f32| if a.normalized() { largest } else { 1.0 };
    fn ints<'a, T: gltf::accessor::Item + std::marker::Copy + Into<f32>>(
        a: gltf::Accessor<'a>,
        get: impl Fn(gltf::Buffer<'a>) -> Option<&'a [u8]> + Clone,
        div: f32,
    ) -> Option<Vec<[f32; 3]>> {
        Some(
            Iter::<[T; 3]>::new(a, get)?
                .map(|v| v.map(|x| x.into() / div))
                .collect(),
        )
    }
    match a.data_type() {
        DataType::F32 => Some(Iter::<[f32; 3]>::new(a, get)?.collect()),
        DataType::I16 => ints::<i16>(a.clone(), get, norm(32767.0)),
        DataType::U16 => ints::<u16>(a.clone(), get, norm(65535.0)),
        DataType::I8 => ints::<i8>(a.clone(), get, norm(127.0)),
        DataType::U8 => ints::<u8>(a.clone(), get, norm(255.0)),
        DataType::U32 => None,
    }
}

#[cfg(test)]
mod tests {
    /// A glTF of one triangle whose positions are `bytes` as `component` (normalized or
    /// not), read back.
    fn read(component: u32, normalized: bool, bytes: &[u8]) -> Option<Vec<[f32; 3]>> {
        let stride = bytes.len() / 3;
        let json = serde_json::json!({
            "asset": {"version": "2.0"},
            "buffers": [{"byteLength": bytes.len()}],
            "bufferViews": [{"buffer": 0, "byteLength": bytes.len(), "byteStride": stride}],
            "accessors": [{"bufferView": 0, "componentType": component, "normalized": normalized,
                "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 1]}],
            "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
        });
        let doc = gltf::Gltf::from_slice_without_validation(json.to_string().as_bytes()).ok()?;
        let prim = doc.meshes().next()?.primitives().next()?;
        super::positions(&prim, |_| Some(bytes))
    }

    #[test]
    fn shorts_are_their_values_or_fractions_when_normalized() {
        let shorts: Vec<u8> = [[1i16, -2, 300, 0], [0, 0, 0, 0], [-32767, 32767, 7, 0]]
            .iter()
            .flatten()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        assert_eq!(
            read(5122, false, &shorts).unwrap(),
            [[1.0, -2.0, 300.0], [0.0; 3], [-32767.0, 32767.0, 7.0]]
        );
        let n = read(5122, true, &shorts).unwrap();
        assert_eq!((n[2][0], n[2][1]), (-1.0, 1.0));
        let floats: Vec<u8> = [0.5f32, 1.0, 2.0, 0.0, 0.0, 0.0, -1.0, -2.0, 3.5]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        assert_eq!(read(5126, false, &floats).unwrap()[2], [-1.0, -2.0, 3.5]);
        let bytes = [255u8, 0, 128, 0, 0, 0, 0, 0, 1, 2, 3, 0];
        assert_eq!(read(5121, false, &bytes).unwrap()[0], [255.0, 0.0, 128.0]);
        assert_eq!(
            read(5121, true, &bytes).unwrap()[0],
            [1.0, 0.0, 128.0 / 255.0]
        );
    }
}
