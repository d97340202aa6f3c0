//! Optotypes and letter charts, sized by the standard 5-arcminute rule: a letter for a minimum
//! angle of resolution MAR (arcmin; MAR = 10^logMAR = 1 / decimal acuity) is 5·MAR tall, its
//! strokes and gaps 1·MAR. Letters are built on a 5 × 5 stroke grid: the tumbling E and the
//! Landolt C (outer diameter 5, stroke 1, parallel-sided gap 1) are exact; the other Sloan
//! letters (C D H K N O R S V Z) are block approximations on the same grid.

use super::mesh::LocalMesh;

/// Letters available in charts and as single optotypes.
pub const SLOAN_LETTERS: [char; 10] = ['C', 'D', 'H', 'K', 'N', 'O', 'R', 'S', 'V', 'Z'];

/// Which way a tumbling E opens or a Landolt C's gap points.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Direction {
    Right,
    Up,
    Left,
    Down,
}

impl Direction {
    pub fn degrees(self) -> f64 {
        match self {
            Direction::Right => 0.0,
            Direction::Up => 90.0,
            Direction::Left => 180.0,
            Direction::Down => 270.0,
        }
    }

    pub fn parse(s: &str) -> Option<Direction> {
        match s.to_ascii_lowercase().as_str() {
            "right" => Some(Direction::Right),
            "up" => Some(Direction::Up),
            "left" => Some(Direction::Left),
            "down" => Some(Direction::Down),
            _ => None,
        }
    }

    const ALL: [Direction; 4] = [
        Direction::Right,
        Direction::Up,
        Direction::Left,
        Direction::Down,
    ];
}

/// A glyph to draw.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Glyph {
    TumblingE(Direction),
    LandoltC(Direction),
    /// One of `SLOAN_LETTERS` (upright).
    Letter(char),
}

/// Letter height (m) for `logmar` at `distance_m`: 5·MAR subtended, exactly.
pub fn letter_height_m(logmar: f64, distance_m: f64) -> f64 {
    let mar_rad = (10f64.powf(logmar) / 60.0).to_radians();
    2.0 * distance_m * (2.5 * mar_rad).tan()
}

fn bitmap(letter: char) -> Option<[&'static str; 5]> {
    Some(match letter {
        'C' => [" ####", "#    ", "#    ", "#    ", " ####"],
        'D' => ["#### ", "#   #", "#   #", "#   #", "#### "],
        'E' => ["#####", "#    ", "#####", "#    ", "#####"],
        'H' => ["#   #", "#   #", "#####", "#   #", "#   #"],
        'K' => ["#   #", "#  # ", "###  ", "#  # ", "#   #"],
        'N' => ["#   #", "##  #", "# # #", "#  ##", "#   #"],
        'O' => [" ### ", "#   #", "#   #", "#   #", " ### "],
        'R' => ["#### ", "#   #", "#### ", "#  # ", "#   #"],
        'S' => [" ####", "#    ", " ### ", "    #", "#### "],
        'V' => ["#   #", "#   #", "#   #", " # # ", "  #  "],
        'Z' => ["#####", "   # ", "  #  ", " #   ", "#####"],
        _ => return None,
    })
}

/// Rotates the local mesh's XY by `degrees` counter-clockwise.
fn rotate(mesh: &mut LocalMesh, degrees: f64) {
    let (s, c) = degrees.to_radians().sin_cos();
    for p in &mut mesh.positions {
        let (x, y) = (p[0], p[1]);
        p[0] = c * x - s * y;
        p[1] = s * x + c * y;
    }
}

/// The glyph as flat geometry facing +Z, centred at the origin, 5 units tall (one unit per
/// stroke), at height `z`.
pub fn glyph_mesh(glyph: Glyph, z: f64) -> LocalMesh {
    let mut m = LocalMesh::default();
    match glyph {
        Glyph::TumblingE(direction) => {
            // Opening to the right: spine on the left, three bars.
            m.rect(-2.5, -2.5, -1.5, 2.5, z);
            for y in [-2.5, -0.5, 1.5] {
                m.rect(-1.5, y, 2.5, y + 1.0, z);
            }
            rotate(&mut m, direction.degrees());
        }
        Glyph::LandoltC(direction) => {
            // Ring of radii 1.5 and 2.5 with a gap of width 1 centred on +X: the gap's edges
            // are the lines y = ±0.5, so the inner and outer arcs start at different angles.
            let (r_in, r_out) = (1.5f64, 2.5f64);
            let a_in = (0.5 / r_in).asin();
            let a_out = (0.5 / r_out).asin();
            let steps = 96u32;
            for i in 0..steps {
                let t0 = f64::from(i) / f64::from(steps);
                let t1 = f64::from(i + 1) / f64::from(steps);
                let angle = |a: f64, t: f64| a + t * (std::f64::consts::TAU - 2.0 * a);
                let point = |r: f64, a: f64| [r * a.cos(), r * a.sin()];
                let p0 = point(r_in, angle(a_in, t0));
                let p1 = point(r_out, angle(a_out, t0));
                let p2 = point(r_out, angle(a_out, t1));
                let p3 = point(r_in, angle(a_in, t1));
                m.flat_triangle([p0, p1, p2], z);
                m.flat_triangle([p0, p2, p3], z);
            }
            rotate(&mut m, direction.degrees());
        }
        Glyph::Letter(letter) => {
            let rows = bitmap(letter).unwrap_or_else(|| bitmap('O').expect("O exists"));
            for (r, row) in rows.iter().enumerate() {
                let y1 = 2.5 - r as f64;
                let bytes = row.as_bytes();
                let mut c = 0;
                while c < 5 {
                    if bytes[c] == b'#' {
                        let start = c;
                        while c < 5 && bytes[c] == b'#' {
                            c += 1;
                        }
                        m.rect(start as f64 - 2.5, y1 - 1.0, c as f64 - 2.5, y1, z);
                    } else {
                        c += 1;
                    }
                }
            }
        }
    }
    m
}

/// Whether a letter can be drawn (single optotypes accept E and the Sloan letters).
pub fn is_known_letter(letter: char) -> bool {
    bitmap(letter).is_some()
}

/// Which glyph family a chart uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ChartStyle {
    Sloan,
    TumblingE,
    LandoltC,
}

/// A deterministic small generator, so that a chart's letters depend only on its seed.
struct Lcg(u64);

impl Lcg {
    fn next(&mut self, n: usize) -> usize {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        ((self.0 >> 33) % n as u64) as usize
    }
}

/// Letters (in units of the letter height `h` of each line), laid out like an ETDRS chart:
/// one letter width between letters, and between lines the height of the next line's letters.
/// Returns the glyph geometry (metres, centred, facing +Z at height `z`) and the chart's
/// width and height in metres.
pub fn chart_mesh(
    lines_logmar: &[f64],
    letters_per_line: u32,
    distance_m: f64,
    style: ChartStyle,
    seed: u64,
    z: f64,
) -> (LocalMesh, f64, f64) {
    let mut rng = Lcg(seed ^ 0x5DEE_CE66_D1CE_4E5B);
    let heights: Vec<f64> = lines_logmar
        .iter()
        .map(|&l| letter_height_m(l, distance_m))
        .collect();
    let n = f64::from(letters_per_line.max(1));
    let width = heights
        .iter()
        .map(|h| (2.0 * n - 1.0) * h)
        .fold(0.0, f64::max);
    let mut total_height = 0.0;
    for (i, h) in heights.iter().enumerate() {
        total_height += h;
        if let Some(next) = heights.get(i + 1) {
            total_height += next;
        }
    }
    let mut mesh = LocalMesh::default();
    let mut top = total_height / 2.0;
    for (i, &h) in heights.iter().enumerate() {
        let line_width = (2.0 * n - 1.0) * h;
        let centre_y = top - h / 2.0;
        let mut previous = usize::MAX;
        for k in 0..letters_per_line.max(1) {
            let glyph = match style {
                ChartStyle::Sloan => {
                    // No letter twice in a row.
                    let mut pick = rng.next(SLOAN_LETTERS.len());
                    if pick == previous {
                        pick = (pick + 1) % SLOAN_LETTERS.len();
                    }
                    previous = pick;
                    Glyph::Letter(SLOAN_LETTERS[pick])
                }
                ChartStyle::TumblingE => Glyph::TumblingE(Direction::ALL[rng.next(4)]),
                ChartStyle::LandoltC => Glyph::LandoltC(Direction::ALL[rng.next(4)]),
            };
            let centre_x = -line_width / 2.0 + h / 2.0 + 2.0 * h * f64::from(k);
            let mut g = glyph_mesh(glyph, 0.0);
            let unit = h / 5.0;
            for p in &mut g.positions {
                p[0] = centre_x + p[0] * unit;
                p[1] = centre_y + p[1] * unit;
                p[2] = z;
            }
            mesh.append(&g);
        }
        top -= h + heights.get(i + 1).copied().unwrap_or(0.0);
    }
    (mesh, width, total_height)
}
