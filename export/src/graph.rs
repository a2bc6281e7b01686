//! A small ONNX graph builder: named values, initialisers and nodes, in order.

use onnx_protobuf::{
    AttributeProto, GraphProto, NodeProto, TensorProto, TensorShapeProto, TypeProto,
    ValueInfoProto,
    attribute_proto::AttributeType,
    tensor_proto::DataType,
    tensor_shape_proto::{Dimension, dimension::Value as DimValue},
    type_proto::{Tensor as TensorType, Value as TypeValue},
};

/// An attribute value.
pub enum Attr {
    /// One integer.
    Int(i64),
    /// A list of integers.
    Ints(Vec<i64>),
    /// One float.
    Float(f32),
}

/// A graph input or output: name, element type, and dimensions (`Ok(size)` fixed,
/// `Err(name)` a named dynamic axis).
pub type Port<'a> = (&'a str, DataType, Vec<Result<i64, &'a str>>);

/// Builds a graph node by node.
#[derive(Default)]
pub struct GraphBuilder {
    nodes: Vec<NodeProto>,
    initializers: Vec<TensorProto>,
    counter: usize,
}

impl GraphBuilder {
    /// A fresh value name with a readable prefix.
    fn fresh(&mut self, hint: &str) -> String {
        self.counter += 1;
        format!("{hint}_{}", self.counter)
    }

    /// A float32 initialiser (raw little-endian data); returns its name.
    pub fn float(&mut self, name: &str, shape: &[usize], values: &[f32]) -> String {
        assert_eq!(shape.iter().product::<usize>(), values.len(), "{name}");
        let mut t = TensorProto::new();
        t.name = name.to_string();
        t.dims = shape.iter().map(|&d| d as i64).collect();
        t.data_type = DataType::FLOAT as i32;
        t.raw_data = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        self.initializers.push(t);
        name.to_string()
    }

    /// An int64 initialiser; returns its name.
    pub fn int64(&mut self, name: &str, values: &[i64]) -> String {
        let mut t = TensorProto::new();
        t.name = name.to_string();
        t.dims = vec![values.len() as i64];
        t.data_type = DataType::INT64 as i32;
        t.raw_data = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        self.initializers.push(t);
        name.to_string()
    }

    /// Adds a node with one output; returns the output's name.
    pub fn op(&mut self, op: &str, inputs: &[&str], attrs: Vec<(&str, Attr)>) -> String {
        let out = self.fresh(&op.to_lowercase());
        self.op_into(op, inputs, attrs, &out);
        out
    }

    /// Adds a node writing to the value `output`.
    pub fn op_into(&mut self, op: &str, inputs: &[&str], attrs: Vec<(&str, Attr)>, output: &str) {
        let mut node = NodeProto::new();
        node.op_type = op.to_string();
        node.name = format!("{op}_{}", self.nodes.len());
        node.input = inputs.iter().map(|s| s.to_string()).collect();
        node.output = vec![output.to_string()];
        for (name, value) in attrs {
            let mut a = AttributeProto::new();
            a.name = name.to_string();
            match value {
                Attr::Int(i) => {
                    a.type_ = AttributeType::INT.into();
                    a.i = i;
                }
                Attr::Ints(v) => {
                    a.type_ = AttributeType::INTS.into();
                    a.ints = v;
                }
                Attr::Float(f) => {
                    a.type_ = AttributeType::FLOAT.into();
                    a.f = f;
                }
            }
            node.attribute.push(a);
        }
        self.nodes.push(node);
    }

    /// Finishes the graph with typed inputs and outputs.
    pub fn finish(self, name: &str, inputs: &[Port<'_>], outputs: &[Port<'_>]) -> GraphProto {
        let info = |(n, ty, dims): &Port<'_>| {
            let mut shape = TensorShapeProto::new();
            for d in dims {
                let mut dim = Dimension::new();
                dim.value = Some(match d {
                    Ok(v) => DimValue::DimValue(*v),
                    Err(p) => DimValue::DimParam(p.to_string()),
                });
                shape.dim.push(dim);
            }
            let mut tensor = TensorType::new();
            tensor.elem_type = *ty as i32;
            tensor.shape = Some(shape).into();
            let mut ty = TypeProto::new();
            ty.value = Some(TypeValue::TensorType(tensor));
            let mut v = ValueInfoProto::new();
            v.name = n.to_string();
            v.type_ = Some(ty).into();
            v
        };
        let mut g = GraphProto::new();
        g.name = name.to_string();
        g.node = self.nodes;
        g.initializer = self.initializers;
        g.input = inputs.iter().map(info).collect();
        g.output = outputs.iter().map(info).collect();
        g
    }
}
