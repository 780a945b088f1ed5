//! Carroll's binary encoding of the factors.
//!
//! Source: `docs/model.md` section 4 ("Binary encoding as in Carroll's GA driver"): a gene
//! of `b` bits, most significant bit first, integer `k` in `[0, 2^b - 1]`,
//! `value = min + (max - min) k / (2^b - 1)`. Genes are concatenated in table order; with
//! Table 1 the chromosome has 93 bits.

use std::fmt;

use serde::{Deserialize, Deserializer, Serialize, Serializer};

use crate::factors::{FACTOR_COUNT, FactorSpec, FactorTable, Factors};

/// Value of gene integer `k` (docs/model.md section 4).
#[inline]
pub fn decode_gene(spec: &FactorSpec, k: u64) -> f64 {
    spec.min + (spec.max - spec.min) * k as f64 / spec.levels_minus_one() as f64
}

/// Integer of the grid point nearest to `value` (clamped into the gene's range).
#[inline]
pub fn nearest_gene(spec: &FactorSpec, value: f64) -> u64 {
    let levels = spec.levels_minus_one();
    let x = ((value - spec.min) / (spec.max - spec.min) * levels as f64).round();
    if x.is_nan() || x <= 0.0 {
        0
    } else if x >= levels as f64 {
        levels
    } else {
        x as u64
    }
}

/// A binary chromosome: the genes of all factors, most significant bit first.
#[derive(Clone, PartialEq, Eq, Hash)]
pub struct Chromosome {
    bits: Vec<bool>,
}

impl Chromosome {
    /// A chromosome from raw bits.
    pub fn from_bits(bits: Vec<bool>) -> Self {
        Chromosome { bits }
    }

    /// The bits.
    pub fn bits(&self) -> &[bool] {
        &self.bits
    }

    /// The bits, mutable (for the genetic operators).
    pub fn bits_mut(&mut self) -> &mut [bool] {
        &mut self.bits
    }

    /// Number of bits.
    pub fn len(&self) -> usize {
        self.bits.len()
    }

    /// Whether the chromosome has no bits.
    pub fn is_empty(&self) -> bool {
        self.bits.is_empty()
    }

    /// Encodes `factors` on the grid of `table` (each value rounded to its nearest grid point).
    pub fn encode(table: &FactorTable, factors: &Factors) -> Chromosome {
        Chromosome::encode_values(&table.0, &factors.0)
    }

    /// Encodes `values` on the grid of `genes` (any number of genes, each value rounded to its
    /// nearest grid point).
    pub fn encode_values(genes: &[FactorSpec], values: &[f64]) -> Chromosome {
        let mut bits = Vec::with_capacity(genes.iter().map(|g| g.bits as usize).sum());
        for (spec, &value) in genes.iter().zip(values) {
            let k = nearest_gene(spec, value);
            for b in (0..spec.bits).rev() {
                bits.push((k >> b) & 1 == 1);
            }
        }
        Chromosome { bits }
    }

    /// Gene integers of all factors, in table order.
    pub fn genes(&self, table: &FactorTable) -> [u64; FACTOR_COUNT] {
        let all = self.gene_integers(&table.0);
        std::array::from_fn(|i| all[i])
    }

    /// Gene integers for the layout `genes`.
    pub fn gene_integers(&self, genes: &[FactorSpec]) -> Vec<u64> {
        let mut out = Vec::with_capacity(genes.len());
        let mut pos = 0;
        for spec in genes {
            let mut k = 0u64;
            for &bit in &self.bits[pos..pos + spec.bits as usize] {
                k = (k << 1) | u64::from(bit);
            }
            out.push(k);
            pos += spec.bits as usize;
        }
        out
    }

    /// Writes gene `index` as the integer `k` (which must fit the gene's bits).
    pub fn set_gene(&mut self, table: &FactorTable, index: usize, k: u64) {
        self.set_gene_integer(&table.0, index, k);
    }

    /// Writes gene `index` of the layout `genes` as the integer `k`.
    pub fn set_gene_integer(&mut self, genes: &[FactorSpec], index: usize, k: u64) {
        let start: usize = genes[..index].iter().map(|s| s.bits as usize).sum();
        let bits = genes[index].bits;
        debug_assert!(k <= genes[index].levels_minus_one());
        for (j, b) in (0..bits).rev().enumerate() {
            self.bits[start + j] = (k >> b) & 1 == 1;
        }
    }

    /// Decodes the factor values.
    pub fn decode(&self, table: &FactorTable) -> Factors {
        let v = self.decode_values(&table.0);
        Factors(std::array::from_fn(|i| v[i]))
    }

    /// Decodes the values of the layout `genes`.
    pub fn decode_values(&self, genes: &[FactorSpec]) -> Vec<f64> {
        self.gene_integers(genes)
            .iter()
            .zip(genes)
            .map(|(&k, spec)| decode_gene(spec, k))
            .collect()
    }
}

impl fmt::Display for Chromosome {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for &b in &self.bits {
            f.write_str(if b { "1" } else { "0" })?;
        }
        Ok(())
    }
}

impl fmt::Debug for Chromosome {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "Chromosome({self})")
    }
}

impl Serialize for Chromosome {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_str(&self.to_string())
    }
}

impl<'de> Deserialize<'de> for Chromosome {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let text = String::deserialize(deserializer)?;
        let bits = text
            .chars()
            .map(|c| match c {
                '0' => Ok(false),
                '1' => Ok(true),
                other => Err(serde::de::Error::custom(format!(
                    "chromosome: expected only '0' and '1', found {other:?}"
                ))),
            })
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Chromosome { bits })
    }
}

#[cfg(test)]
#[allow(clippy::float_cmp)] // these tests check exact values on purpose
mod tests {
    use super::*;

    #[test]
    fn every_grid_point_of_every_factor_round_trips() {
        let table = FactorTable::default();
        for (i, spec) in table.0.iter().enumerate() {
            for k in 0..=spec.levels_minus_one() {
                let value = decode_gene(spec, k);
                assert!(spec.contains(value), "factor {i} k {k} value {value}");
                assert_eq!(nearest_gene(spec, value), k);
                let mut factors = Factors::NOMINAL;
                factors.0[i] = value;
                let c = Chromosome::encode(&table, &factors);
                assert_eq!(c.len(), 93);
                assert_eq!(c.genes(&table)[i], k);
                assert_eq!(c.decode(&table).0[i].to_bits(), value.to_bits());
            }
        }
    }

    #[test]
    fn ends_of_the_gene_are_the_bounds() {
        let table = FactorTable::default();
        for spec in &table.0 {
            assert_eq!(decode_gene(spec, 0), spec.min);
            assert!((decode_gene(spec, spec.levels_minus_one()) - spec.max).abs() < 1e-15);
        }
    }

    #[test]
    fn most_significant_bit_first() {
        let table = FactorTable::default();
        let mut c = Chromosome::encode(&table, &Factors::NOMINAL);
        c.set_gene(&table, 0, 1);
        assert!(c.bits()[4] && !c.bits()[0]);
        c.set_gene(&table, 0, 16);
        assert!(c.bits()[0] && !c.bits()[4]);
    }

    #[test]
    fn serde_round_trip() {
        let table = FactorTable::default();
        let c = Chromosome::encode(&table, &Factors::TRUTH);
        let json = serde_json::to_string(&c).unwrap();
        let back: Chromosome = serde_json::from_str(&json).unwrap();
        assert_eq!(back, c);
        assert!(serde_json::from_str::<Chromosome>("\"012\"").is_err());
    }
}
