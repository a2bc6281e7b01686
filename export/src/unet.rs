//! The QnA-UNet as an ONNX graph (SPEC §3), layout `[B, C, N]`, opset 17, using only operators
//! that onnxruntime, Unity's inference engine and Unreal NNE all run.

use onnx_protobuf::{GraphProto, tensor_proto::DataType};

use crate::ExportError;
use crate::graph::{Attr, GraphBuilder};
use crate::weights::get;
use sinmdm::network::{
    BATCH_AXIS, CONV_KERNEL, EMBEDDING_MULTIPLIER, FRAMES_AXIS, INPUT_FEATURES, INPUT_STEP,
    NORM_EPSILON, NORM_GROUPS, NetworkShape, OUTPUT_FEATURES, SCORE_FLOOR, SINUSOID_WIDTH, Weights,
    position_weights, timestep_frequencies,
};

struct Net<'a> {
    b: GraphBuilder,
    w: &'a Weights,
    shape: NetworkShape,
    one: String,
}

impl Net<'_> {
    fn silu(&mut self, x: &str) -> String {
        let s = self.b.op("Sigmoid", &[x], vec![]);
        self.b.op("Mul", &[x, &s], vec![])
    }

    /// Conv over frames from a `[k, C_in, C_out]` weight.
    fn conv(
        &mut self,
        x: &str,
        prefix: &str,
        cin: usize,
        cout: usize,
        k: usize,
    ) -> Result<String, ExportError> {
        let w = get(self.w, &format!("{prefix}.weight"), &[k, cin, cout])?;
        let bias = get(self.w, &format!("{prefix}.bias"), &[cout])?;
        let mut t = vec![0f32; cout * cin * k];
        for j in 0..k {
            for i in 0..cin {
                for o in 0..cout {
                    t[(o * cin + i) * k + j] = w.values[(j * cin + i) * cout + o];
                }
            }
        }
        let wn = self
            .b
            .float(&format!("{prefix}.weight"), &[cout, cin, k], &t);
        let bn = self
            .b
            .float(&format!("{prefix}.bias"), &[cout], &bias.values);
        let pad = ((k - 1) / 2) as i64;
        Ok(self.b.op(
            "Conv",
            &[x, &wn, &bn],
            vec![
                ("kernel_shape", Attr::Ints(vec![k as i64])),
                ("pads", Attr::Ints(vec![pad, pad])),
            ],
        ))
    }

    /// GroupNorm(32) as Reshape -> InstanceNormalization -> Reshape -> Mul -> Add.
    fn group_norm(
        &mut self,
        x: &str,
        prefix: &str,
        channels: usize,
    ) -> Result<String, ExportError> {
        let gamma = get(self.w, &format!("{prefix}.gamma"), &[channels])?
            .values
            .clone();
        let beta = get(self.w, &format!("{prefix}.beta"), &[channels])?
            .values
            .clone();
        let shape = self.b.op("Shape", &[x], vec![]);
        let grouped = self.b.op("Reshape", &[x, "groups_shape"], vec![]);
        let normed = self.b.op(
            "InstanceNormalization",
            &[&grouped, "groups_ones", "groups_zeros"],
            vec![("epsilon", Attr::Float(NORM_EPSILON))],
        );
        let back = self.b.op("Reshape", &[&normed, &shape], vec![]);
        let g = self
            .b
            .float(&format!("{prefix}.gamma"), &[channels, 1], &gamma);
        let be = self
            .b
            .float(&format!("{prefix}.beta"), &[channels, 1], &beta);
        let scaled = self.b.op("Mul", &[&back, &g], vec![]);
        Ok(self.b.op("Add", &[&scaled, &be], vec![]))
    }

    fn linear(
        &mut self,
        x: &str,
        prefix: &str,
        din: usize,
        dout: usize,
    ) -> Result<String, ExportError> {
        let w = get(self.w, &format!("{prefix}.weight"), &[din, dout])?
            .values
            .clone();
        let bias = get(self.w, &format!("{prefix}.bias"), &[dout])?
            .values
            .clone();
        let wn = self.b.float(&format!("{prefix}.weight"), &[din, dout], &w);
        let bn = self.b.float(&format!("{prefix}.bias"), &[dout], &bias);
        let m = self.b.op("MatMul", &[x, &wn], vec![]);
        Ok(self.b.op("Add", &[&m, &bn], vec![]))
    }

    fn resblock(
        &mut self,
        x: &str,
        prefix: &str,
        cin: usize,
        cout: usize,
        emb: &str,
    ) -> Result<String, ExportError> {
        let c = self.shape.channels;
        let n = self.group_norm(x, &format!("{prefix}.in_norm"), cin)?;
        let a = self.silu(&n);
        let h = self.conv(&a, &format!("{prefix}.in_conv"), cin, cout, CONV_KERNEL)?;
        let ss = self.linear(
            emb,
            &format!("{prefix}.embedding"),
            EMBEDDING_MULTIPLIER * c,
            2 * cout,
        )?;
        let ss = self.b.op("Unsqueeze", &[&ss, "axis_2"], vec![]);
        let scale = self.b.op(
            "Slice",
            &[&ss, "zero_1", &format!("{prefix}.split"), "axis_1"],
            vec![],
        );
        let shift = self.b.op(
            "Slice",
            &[
                &ss,
                &format!("{prefix}.split"),
                &format!("{prefix}.end"),
                "axis_1",
            ],
            vec![],
        );
        let hn = self.group_norm(&h, &format!("{prefix}.out_norm"), cout)?;
        let scale1 = self.b.op("Add", &[&scale, &self.one.clone()], vec![]);
        let hs = self.b.op("Mul", &[&hn, &scale1], vec![]);
        let hs = self.b.op("Add", &[&hs, &shift], vec![]);
        let a = self.silu(&hs);
        let h = self.conv(&a, &format!("{prefix}.out_conv"), cout, cout, CONV_KERNEL)?;
        let skip = if cin != cout {
            self.conv(x, &format!("{prefix}.skip"), cin, cout, 1)?
        } else {
            x.to_string()
        };
        Ok(self.b.op("Add", &[&skip, &h], vec![]))
    }

    fn qna(&mut self, x: &str, prefix: &str) -> Result<String, ExportError> {
        let NetworkShape {
            channels: c,
            heads: h,
            window: k,
            ..
        } = self.shape;
        let d = c / h;
        let pad = ((k - 1) / 2) as i64;
        let xn = self.group_norm(x, &format!("{prefix}.norm"), c)?;
        // Scores through the equivalent C -> H projection of the normalised query.
        let q = &get(self.w, &format!("{prefix}.query"), &[c])?.values;
        let wk = &get(self.w, &format!("{prefix}.key_weight"), &[c, c])?.values;
        let bk = &get(self.w, &format!("{prefix}.key_bias"), &[c])?.values;
        let mut weff = vec![0f32; h * c];
        let mut beff = vec![0f32; h];
        for head in 0..h {
            let norm = (0..d)
                .map(|j| f64::from(q[head * d + j]).powi(2))
                .sum::<f64>()
                .sqrt()
                .max(1e-12);
            let qn: Vec<f64> = (0..d)
                .map(|j| f64::from(q[head * d + j]) / norm / (d as f64).sqrt())
                .collect();
            for ci in 0..c {
                weff[head * c + ci] = (0..d)
                    .map(|j| qn[j] * f64::from(wk[(head * d + j) * c + ci]))
                    .sum::<f64>() as f32;
            }
            beff[head] = (0..d)
                .map(|j| qn[j] * f64::from(bk[head * d + j]))
                .sum::<f64>() as f32;
        }
        let wn = self
            .b
            .float(&format!("{prefix}.score_weight"), &[h, c, 1], &weff);
        let bn = self.b.float(&format!("{prefix}.score_bias"), &[h], &beff);
        let scores = self.b.op(
            "Conv",
            &[&xn, &wn, &bn],
            vec![("kernel_shape", Attr::Ints(vec![1]))],
        );
        let top = self.b.op(
            "ReduceMax",
            &[&scores],
            vec![("axes", Attr::Ints(vec![2])), ("keepdims", Attr::Int(1))],
        );
        let diff = self.b.op("Sub", &[&scores, &top], vec![]);
        let floored = self.b.op("Max", &[&diff, "score_floor"], vec![]);
        let e = self.b.op("Exp", &[&floored], vec![]);
        let v = self.conv(&xn, &format!("{prefix}.value"), c, c, 1)?;
        let v4 = self.b.op("Reshape", &[&v, "heads_shape"], vec![]);
        let e4 = self.b.op("Unsqueeze", &[&e, "axis_2"], vec![]);
        let weighted = self.b.op("Mul", &[&v4, &e4], vec![]);
        let weighted = self.b.op("Reshape", &[&weighted, "channels_shape"], vec![]);
        let rpe = &get(self.w, &format!("{prefix}.rpe"), &[h, k])?.values;
        // Every weight in (0, 1], so the window sums below can neither overflow nor, with the
        // score floor, underflow to 0.
        let bias = position_weights(rpe, k);
        let per_channel: Vec<f32> = (0..c)
            .flat_map(|ch| bias[(ch / d) * k..(ch / d + 1) * k].to_vec())
            .collect();
        let wc = self.b.float(
            &format!("{prefix}.window_channels"),
            &[c, 1, k],
            &per_channel,
        );
        let wh = self
            .b
            .float(&format!("{prefix}.window_heads"), &[h, 1, k], &bias);
        let window = |groups: usize| {
            vec![
                ("kernel_shape", Attr::Ints(vec![k as i64])),
                ("pads", Attr::Ints(vec![pad, pad])),
                ("group", Attr::Int(groups as i64)),
            ]
        };
        let num = self.b.op("Conv", &[&weighted, &wc], window(c));
        let den = self.b.op("Conv", &[&e, &wh], window(h));
        let num4 = self.b.op("Reshape", &[&num, "heads_shape"], vec![]);
        let den4 = self.b.op("Unsqueeze", &[&den, "axis_2"], vec![]);
        let att = self.b.op("Div", &[&num4, &den4], vec![]);
        let att = self.b.op("Reshape", &[&att, "channels_shape"], vec![]);
        let out = self.conv(&att, &format!("{prefix}.proj"), c, c, 1)?;
        Ok(self.b.op("Add", &[x, &out], vec![]))
    }
}

/// Builds the denoiser graph `x_t [B, F, N], t [B] -> x0 [B, F, N]` from named weights.
pub fn build(weights: &Weights, shape: NetworkShape) -> Result<GraphProto, ExportError> {
    let NetworkShape {
        features: f,
        channels: c,
        heads: h,
        window: _,
    } = shape;
    shape.check().map_err(ExportError::BadShape)?;
    let mut b = GraphBuilder::default();
    b.int64("groups_shape", &[0, NORM_GROUPS as i64, -1]);
    b.float("groups_ones", &[NORM_GROUPS], &[1.0; NORM_GROUPS]);
    b.float("groups_zeros", &[NORM_GROUPS], &[0.0; NORM_GROUPS]);
    b.int64("heads_shape", &[0, h as i64, (c / h) as i64, -1]);
    b.int64("channels_shape", &[0, c as i64, -1]);
    b.int64("axis_1", &[1]);
    b.int64("axis_2", &[2]);
    b.int64("zero_1", &[0]);
    b.float("score_floor", &[1], &[SCORE_FLOOR]);
    let one = b.float("one", &[1], &[1.0]);
    for (prefix, cout) in [("block1", c), ("block2", c), ("block3", c)] {
        b.int64(&format!("{prefix}.split"), &[cout as i64]);
        b.int64(&format!("{prefix}.end"), &[2 * cout as i64]);
    }
    let freqs = timestep_frequencies();
    b.float("time_frequencies", &[1, freqs.len()], &freqs);
    let mut net = Net {
        b,
        w: weights,
        shape,
        one,
    };

    let tf = net.b.op(
        "Cast",
        &[INPUT_STEP],
        vec![("to", Attr::Int(DataType::FLOAT as i64))],
    );
    let tu = net.b.op("Unsqueeze", &[&tf, "axis_1"], vec![]);
    let args = net.b.op("Mul", &[&tu, "time_frequencies"], vec![]);
    let cos = net.b.op("Cos", &[&args], vec![]);
    let sin = net.b.op("Sin", &[&args], vec![]);
    let sinusoid = net
        .b
        .op("Concat", &[&cos, &sin], vec![("axis", Attr::Int(1))]);
    let e = net.linear(
        &sinusoid,
        "time.first",
        SINUSOID_WIDTH,
        EMBEDDING_MULTIPLIER * c,
    )?;
    let e = net.silu(&e);
    let e = net.linear(
        &e,
        "time.second",
        EMBEDDING_MULTIPLIER * c,
        EMBEDDING_MULTIPLIER * c,
    )?;
    let emb = net.silu(&e);

    let h0 = net.conv(INPUT_FEATURES, "input", f, c, CONV_KERNEL)?;
    let h1 = net.resblock(&h0, "block1", c, c, &emb)?;
    let h1 = net.qna(&h1, "attention1")?;
    let h2 = net.resblock(&h1, "block2", c, c, &emb)?;
    let h2 = net.qna(&h2, "attention2")?;
    let cat = net
        .b
        .op("Concat", &[&h2, &h0], vec![("axis", Attr::Int(1))]);
    let h3 = net.resblock(&cat, "block3", 2 * c, c, &emb)?;
    let h3 = net.qna(&h3, "attention3")?;
    let n = net.group_norm(&h3, "out_norm", c)?;
    let a = net.silu(&n);
    let out = net.conv(&a, "output", c, f, CONV_KERNEL)?;
    net.b.op_into("Identity", &[&out], vec![], OUTPUT_FEATURES);
    let fi = f as i64;
    Ok(net.b.finish(
        "sinmdm_qna_unet",
        &[
            (
                INPUT_FEATURES,
                DataType::FLOAT,
                vec![Err(BATCH_AXIS), Ok(fi), Err(FRAMES_AXIS)],
            ),
            (INPUT_STEP, DataType::INT64, vec![Err(BATCH_AXIS)]),
        ],
        &[(
            OUTPUT_FEATURES,
            DataType::FLOAT,
            vec![Err(BATCH_AXIS), Ok(fi), Err(FRAMES_AXIS)],
        )],
    ))
}
