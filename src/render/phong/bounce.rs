//! The one-bounce kernel (`effects::one_bounce`): which virtual point
//! lights each hit sees and with what geometric factor, from the hits'
//! positions and normals alone, so that `Packed` can keep it for a session.

/// Virtual point lights of the one-bounce estimate.
const BOUNCE_LIGHTS: usize = 64;
/// Keeps the one-bounce kernel finite where two hits nearly touch (m^2).
const BOUNCE_EPS: f32 = 0.01;

/// The one-bounce kernel of a set of hits: for each hit, the virtual
/// point lights (hits spread evenly through the list) it sees and the
/// geometric factor cos_i cos_j / (d^2 (d^2 + eps)) of each. It depends
/// on the hits alone, so a session whose geometry does not move computes
/// it once (`Packed::bounce`) and a render only weighs the lights' colours.
pub struct Bounce {
    /// Packed index of each virtual point light.
    pub vpl: Vec<usize>,
    /// `terms[offsets[i]..offsets[i + 1]]`: hit i's (light, factor) pairs.
    pub offsets: Vec<u32>,
    pub terms: Vec<(u16, f32)>,
}

impl Bounce {
    /// The kernel of hits at positions `p` with normals `nrm` (columns x,
    /// y, z of equal length).
    pub fn new(p: [&[f32]; 3], nrm: [&[f32]; 3]) -> Bounce {
        let ([px, py, pz], [nxs, nys, nzs]) = (p, nrm);
        let n = px.len();
        let stride = (n / BOUNCE_LIGHTS).max(1);
        let vpl: Vec<usize> = (stride / 2..n)
            .step_by(stride)
            .take(BOUNCE_LIGHTS)
            .collect();
        let mut offsets = Vec::with_capacity(n + 1);
        let mut terms = Vec::new();
        offsets.push(0);
        for i in 0..n {
            let (x, y, z) = (px[i], py[i], pz[i]);
            let (nx, ny, nz) = (nxs[i], nys[i], nzs[i]);
            for (s, &j) in vpl.iter().enumerate() {
                let (wx, wy, wz) = (px[j] - x, py[j] - y, pz[j] - z);
                let ci = nx * wx + ny * wy + nz * wz;
                let cj = -(nxs[j] * wx + nys[j] * wy + nzs[j] * wz);
                if ci <= 0.0 || cj <= 0.0 {
                    continue;
                }
                let d2 = wx * wx + wy * wy + wz * wz;
                terms.push((s as u16, ci * cj / (d2 * (d2 + BOUNCE_EPS))));
            }
            offsets.push(terms.len() as u32);
        }
        Bounce {
            vpl,
            offsets,
            terms,
        }
    }
}
