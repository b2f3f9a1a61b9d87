//! Which law the data support: each law's best fit ranked by Akaike's information
//! criterion (AIC = −2 ln L + 2k; Akaike, IEEE Trans. Autom. Control 19, 716, 1974) and
//! the Bayesian one (BIC = −2 ln L + k ln n; Schwarz, Ann. Stat. 6, 461, 1978), with the
//! Akaike weights and a verdict in words (Burnham & Anderson, Model Selection and
//! Multimodel Inference, 2002, §2.6: ΔAIC below 2 leaves both laws supported, above 10
//! leaves the worse essentially none).

use super::solve::FitReport;
use serde::Serialize;

/// ΔAIC below which two laws are equally supported.
pub const CANNOT_TELL: f64 = 2.0;
/// ΔAIC above which the worse law has essentially no support.
pub const DECISIVE: f64 = 10.0;

/// One law's fit, as the comparison ranks it.
#[derive(Debug, Clone, Serialize)]
pub struct LawScore {
    /// The law's name.
    pub law: String,
    /// Parameters fitted.
    pub parameters: usize,
    /// Its χ² (with the weights given, or the default relative ones where the standard
    /// deviations are estimated).
    pub chi_square: f64,
    /// −2 ln L up to a constant all laws share: χ² with the standard deviations given,
    /// n ln(χ²/n) with them estimated.
    pub minus_two_log_likelihood: f64,
    /// Akaike's information criterion.
    pub aic: f64,
    /// The Bayesian information criterion.
    pub bic: f64,
    /// AIC less the best law's.
    pub delta_aic: f64,
    /// exp(−ΔAIC/2), normalised over the laws.
    pub akaike_weight: f64,
    /// Whether its fit describes the data at all (see the fit's diagnosis).
    pub describes_data: bool,
}

/// The laws ranked, best first, and what the data say.
#[derive(Debug, Clone, Serialize)]
pub struct LawComparison {
    /// Each law, best (least AIC) first.
    pub ranking: Vec<LawScore>,
    /// The verdict in words.
    pub verdict: String,
    /// Whether the data single out one law (the runner-up's ΔAIC is at least
    /// [`CANNOT_TELL`] and the best describes the data).
    pub decided: bool,
}

/// Rank the fits `fits` (law name, its report) of one data set.
/// Where the fits left out points that graze a switch ([`FitReport::left_out`]), they
/// are compared over the points none of them left out.
pub fn compare(fits: &[(String, &FitReport)]) -> LawComparison {
    let mut union: Vec<usize> = fits
        .iter()
        .flat_map(|(_, r)| r.left_out.iter().copied())
        .collect();
    union.sort_unstable();
    union.dedup();
    let mut ranking: Vec<LawScore> = fits
        .iter()
        .map(|(law, r)| {
            let (chi_square, count) = common_chi_square(r, &union);
            let n = count as f64;
            let k = r.parameters.len() as f64;
            let m2ll = if r.sigma_estimated {
                n * (chi_square.max(f64::MIN_POSITIVE) / n).ln()
            } else {
                chi_square
            };
            LawScore {
                law: law.clone(),
                parameters: r.parameters.len(),
                chi_square,
                minus_two_log_likelihood: m2ll,
                aic: m2ll + 2.0 * k,
                bic: m2ll + k * n.ln(),
                delta_aic: 0.0,
                akaike_weight: 0.0,
                describes_data: r.diagnosis.describes_data,
            }
        })
        .collect();
    ranking.sort_by(|a, b| a.aic.total_cmp(&b.aic));
    let best = ranking.first().map_or(0.0, |s| s.aic);
    for s in &mut ranking {
        s.delta_aic = s.aic - best;
    }
    let total: f64 = ranking.iter().map(|s| (-s.delta_aic / 2.0).exp()).sum();
    for s in &mut ranking {
        s.akaike_weight = (-s.delta_aic / 2.0).exp() / total;
    }
    let (mut verdict, decided) = verdict(&ranking);
    if !union.is_empty() {
        verdict.push_str(&format!(
            " (compared without the {} points a fit left out as grazing a switch)",
            union.len()
        ));
    }
    LawComparison {
        ranking,
        verdict,
        decided,
    }
}

/// χ² of `r` over the data's points not in `left_out` (indices, increasing; a superset
/// of the report's own), and the residuals counted.
fn common_chi_square(r: &FitReport, left_out: &[usize]) -> (f64, usize) {
    let kept_n = r.fitted.phase_deg.len().max(1);
    let total = kept_n + r.left_out.len();
    let kept: Vec<usize> = (0..total)
        .filter(|i| r.left_out.binary_search(i).is_err())
        .collect();
    let mut sum = 0.0;
    let mut count = 0;
    for (k, x) in r.residuals.iter().enumerate() {
        if kept
            .get(k % kept_n)
            .is_some_and(|i| left_out.binary_search(i).is_err())
        {
            sum += x * x;
            count += 1;
        }
    }
    (sum, count)
}

/// The verdict on a ranking, and whether it decides.
fn verdict(ranking: &[LawScore]) -> (String, bool) {
    let Some(best) = ranking.first() else {
        return ("no law was fitted".into(), false);
    };
    let Some(next) = ranking.get(1) else {
        return (
            format!("only {} was fitted: nothing to compare", best.law),
            false,
        );
    };
    if !best.describes_data {
        return (
            format!(
                "none of the laws describes these data (the best, {}, leaves structure in \
                 its residuals or a χ² far above its noise): the ranking says which misses \
                 less, not which is right",
                best.law
            ),
            false,
        );
    }
    let d_chi = next.chi_square - best.chi_square;
    let same_k = next.parameters == best.parameters;
    let by = if same_k {
        format!("Δχ² = {d_chi:.1}, ΔAIC = {:.1}", next.delta_aic)
    } else {
        format!(
            "ΔAIC = {:.1} ({} against {} parameters)",
            next.delta_aic, best.parameters, next.parameters
        )
    };
    if next.delta_aic < CANNOT_TELL {
        (
            format!(
                "the data cannot tell {} from {} ({by}): both describe them within their \
                 noise — data that the laws predict differently (the branch jump, the \
                 repulsive branch, a larger amplitude) would",
                best.law, next.law
            ),
            false,
        )
    } else if next.delta_aic < DECISIVE {
        (
            format!(
                "the data favour {} over {} ({by}; Akaike weight {:.3}), not decisively",
                best.law, next.law, best.akaike_weight
            ),
            true,
        )
    } else {
        (
            format!(
                "the data prefer {} over {} by {by} (Akaike weight {:.3})",
                best.law, next.law, best.akaike_weight
            ),
            true,
        )
    }
}
