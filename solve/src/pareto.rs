//! Pareto ranking and crowding distance for two minimised objectives.
//!
//! Source: K. Deb et al., "A fast and elitist multiobjective genetic algorithm: NSGA-II",
//! IEEE Trans. Evol. Comput. 6(2), 2002: fast non-dominated sorting (section III-A) and the
//! crowding distance (section III-B). Anderson's study ranks its population the same way
//! ("binary tournament selection on Pareto rank, then crowding distance").
//!
//! A run that did not finish has objectives (inf, inf): every finished run dominates it, and
//! such runs do not dominate each other.

/// Whether `a` dominates `b`: no worse in both objectives and better in at least one.
#[inline]
pub fn dominates(a: &[f64; 2], b: &[f64; 2]) -> bool {
    a[0] <= b[0] && a[1] <= b[1] && (a[0] < b[0] || a[1] < b[1])
}

/// Fronts of the points (indices), best first: front 0 is the non-dominated set, front 1 is
/// non-dominated once front 0 is removed, and so on. Indices within a front are increasing.
pub fn non_dominated_fronts(points: &[[f64; 2]]) -> Vec<Vec<usize>> {
    let n = points.len();
    let mut dominated_by_count = vec![0usize; n];
    let mut dominates_list: Vec<Vec<usize>> = vec![Vec::new(); n];
    for i in 0..n {
        for j in (i + 1)..n {
            if dominates(&points[i], &points[j]) {
                dominates_list[i].push(j);
                dominated_by_count[j] += 1;
            } else if dominates(&points[j], &points[i]) {
                dominates_list[j].push(i);
                dominated_by_count[i] += 1;
            }
        }
    }
    let mut fronts = Vec::new();
    let mut current: Vec<usize> = (0..n).filter(|&i| dominated_by_count[i] == 0).collect();
    while !current.is_empty() {
        let mut next = Vec::new();
        for &i in &current {
            for &j in &dominates_list[i] {
                dominated_by_count[j] -= 1;
                if dominated_by_count[j] == 0 {
                    next.push(j);
                }
            }
        }
        next.sort_unstable();
        fronts.push(current);
        current = next;
    }
    fronts
}

/// Pareto rank of every point (0 = non-dominated).
pub fn ranks(points: &[[f64; 2]]) -> Vec<usize> {
    let mut rank = vec![0; points.len()];
    for (r, front) in non_dominated_fronts(points).iter().enumerate() {
        for &i in front {
            rank[i] = r;
        }
    }
    rank
}

/// Crowding distance of each member of one front (`front` holds indices into `points`); the
/// result is in the order of `front`. Boundary points get infinity; a member's distance is the
/// sum over objectives of the gap between its neighbours, normalised by the front's range.
/// Objectives that are not finite (runs that did not finish) contribute nothing.
#[allow(clippy::needless_range_loop)] // `obj` picks the objective of every point
pub fn crowding_distances(points: &[[f64; 2]], front: &[usize]) -> Vec<f64> {
    let m = front.len();
    let mut dist = vec![0.0; m];
    if m <= 2 {
        return vec![f64::INFINITY; m];
    }
    for obj in 0..2 {
        let mut order: Vec<usize> = (0..m).collect();
        // Stable sort: ties keep index order, so the result is deterministic.
        order.sort_by(|&a, &b| points[front[a]][obj].total_cmp(&points[front[b]][obj]));
        let lo = points[front[order[0]]][obj];
        let hi = points[front[order[m - 1]]][obj];
        dist[order[0]] = f64::INFINITY;
        dist[order[m - 1]] = f64::INFINITY;
        let range = hi - lo;
        if !(range.is_finite() && range > 0.0) {
            continue;
        }
        for k in 1..m - 1 {
            let gap = points[front[order[k + 1]]][obj] - points[front[order[k - 1]]][obj];
            dist[order[k]] += gap / range;
        }
    }
    dist
}

/// Rank and crowding distance of every point.
pub fn rank_and_crowding(points: &[[f64; 2]]) -> (Vec<usize>, Vec<f64>) {
    let mut rank = vec![0; points.len()];
    let mut crowd = vec![0.0; points.len()];
    for (r, front) in non_dominated_fronts(points).iter().enumerate() {
        for (&i, d) in front.iter().zip(crowding_distances(points, front)) {
            rank[i] = r;
            crowd[i] = d;
        }
    }
    (rank, crowd)
}

/// The crowded-comparison order: lower rank wins; at equal rank, larger crowding distance wins.
#[inline]
pub fn crowded_better(rank_a: usize, crowd_a: f64, rank_b: usize, crowd_b: f64) -> bool {
    rank_a < rank_b || (rank_a == rank_b && crowd_a > crowd_b)
}

/// Elitist environmental selection: the indices of the `keep` best points by rank, filling the
/// last front that does not fit whole by decreasing crowding distance (ties by index).
pub fn select_best(points: &[[f64; 2]], keep: usize) -> Vec<usize> {
    let mut chosen = Vec::with_capacity(keep);
    for front in non_dominated_fronts(points) {
        if chosen.len() + front.len() <= keep {
            chosen.extend_from_slice(&front);
        } else {
            let d = crowding_distances(points, &front);
            let mut order: Vec<usize> = (0..front.len()).collect();
            order.sort_by(|&a, &b| d[b].total_cmp(&d[a]).then(front[a].cmp(&front[b])));
            for &k in order.iter().take(keep - chosen.len()) {
                chosen.push(front[k]);
            }
        }
        if chosen.len() == keep {
            break;
        }
    }
    chosen
}

/// Hypervolume of the points dominated by a two-objective set and bounded by `reference`
/// (both minimised); points not strictly better than the reference in both objectives
/// contribute nothing.
pub fn hypervolume(points: &[[f64; 2]], reference: [f64; 2]) -> f64 {
    let mut inside: Vec<[f64; 2]> = points
        .iter()
        .copied()
        .filter(|p| p[0] < reference[0] && p[1] < reference[1])
        .collect();
    inside.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    let mut volume = 0.0;
    let mut best_y = reference[1];
    for p in inside {
        if p[1] < best_y {
            volume += (reference[0] - p[0]) * (best_y - p[1]);
            best_y = p[1];
        }
    }
    volume
}

#[cfg(test)]
#[allow(clippy::float_cmp)] // hand-worked values are exact
mod tests {
    use super::*;

    #[test]
    fn dominance() {
        assert!(dominates(&[1.0, 1.0], &[2.0, 2.0]));
        assert!(dominates(&[1.0, 2.0], &[1.0, 3.0]));
        assert!(!dominates(&[1.0, 2.0], &[1.0, 2.0]));
        assert!(!dominates(&[1.0, 3.0], &[2.0, 2.0]));
        let inf = f64::INFINITY;
        assert!(dominates(&[1e9, 1e9], &[inf, inf]));
        assert!(!dominates(&[inf, inf], &[inf, inf]));
    }

    #[test]
    fn hand_worked_fronts() {
        // 0:(1,5) 1:(2,3) 2:(4,1) front 0; 3:(3,4) dominated by 1; 4:(5,5) dominated by all;
        // 5:(inf,inf) last.
        let inf = f64::INFINITY;
        let p = [
            [1.0, 5.0],
            [2.0, 3.0],
            [4.0, 1.0],
            [3.0, 4.0],
            [5.0, 5.0],
            [inf, inf],
        ];
        assert_eq!(
            non_dominated_fronts(&p),
            vec![vec![0, 1, 2], vec![3], vec![4], vec![5]]
        );
        assert_eq!(ranks(&p), vec![0, 0, 0, 1, 2, 3]);
    }

    #[test]
    fn hand_worked_crowding() {
        // Front (1,5), (2,3), (4,1), (3,2): sorted by f1: 0,1,3,2; by f2: 2,3,1,0.
        // f1 range 3, f2 range 4.
        // point 1 (2,3): f1 neighbours 1 and 3 -> 2/3; f2 neighbours 2 and 5 -> 3/4.
        // point 3 (3,2): f1 neighbours 2 and 4 -> 2/3; f2 neighbours 1 and 3 -> 2/4.
        let p = [[1.0, 5.0], [2.0, 3.0], [4.0, 1.0], [3.0, 2.0]];
        let d = crowding_distances(&p, &[0, 1, 2, 3]);
        assert_eq!(d[0], f64::INFINITY);
        assert_eq!(d[2], f64::INFINITY);
        assert!((d[1] - (2.0 / 3.0 + 3.0 / 4.0)).abs() < 1e-15);
        assert!((d[3] - (2.0 / 3.0 + 2.0 / 4.0)).abs() < 1e-15);
        assert_eq!(crowding_distances(&p, &[0, 1]), vec![f64::INFINITY; 2]);
    }

    #[test]
    fn selection_keeps_fronts_then_the_least_crowded() {
        let p = [
            [1.0, 5.0],
            [2.0, 3.0],
            [4.0, 1.0],
            [3.0, 2.0],
            [5.0, 6.0],
            [2.1, 2.9],
        ];
        // Front 0: 0, 1, 2, 3, 5; front 1: 4. Crowding in front 0 (ranges 3 and 4): the
        // boundaries 0 and 2 are infinite; 1: 1.1/3 + 2.1/4; 3: 1.9/3 + 1.9/4; 5: 1/3 + 1/4.
        assert_eq!(select_best(&p, 3), vec![0, 2, 3]);
        assert_eq!(select_best(&p, 4), vec![0, 2, 3, 1]);
        assert_eq!(select_best(&p, 6), vec![0, 1, 2, 3, 5, 4]);
    }

    #[test]
    fn hypervolume_of_a_staircase() {
        let p = [[0.0, 1.0], [0.5, 0.5], [1.0, 0.0]];
        // Reference (1.1, 1.1): strips 1.1*0.1 + 0.6*0.5 + 0.1*0.5 = 0.11 + 0.3 + 0.05.
        let hv = hypervolume(&p, [1.1, 1.1]);
        assert!((hv - 0.46).abs() < 1e-12, "{hv}");
        assert_eq!(hypervolume(&[[2.0, 0.0]], [1.1, 1.1]), 0.0);
    }
}
