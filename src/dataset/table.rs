//! Columns written to Parquet with the `parquet` crate's column writers, in the shapes pyarrow
//! writes them: every field nullable (`optional`), lists as the standard three-level `LIST`
//! (`optional group NAME (LIST) { repeated group list { optional T element; } }`), strings as
//! `BYTE_ARRAY (String)`, Snappy compression, one row group per [`Table`] written.

use std::fs::File;
use std::sync::Arc;

use parquet::basic::{Compression, LogicalType, Repetition, Type as Physical};
use parquet::data_type::{ByteArray, ByteArrayType, DoubleType, FloatType, Int64Type};
use parquet::file::metadata::KeyValue;
use parquet::file::properties::WriterProperties;
use parquet::file::writer::SerializedFileWriter;
use parquet::schema::types::{Type, TypePtr};

/// One column's values for the rows of a [`Table`].
#[derive(Debug, Clone, PartialEq)]
pub enum Column {
    /// `float` per row.
    F32(Vec<f32>),
    /// `double` per row.
    F64(Vec<f64>),
    /// `int64` per row.
    I64(Vec<i64>),
    /// UTF-8 string per row.
    Str(Vec<String>),
    /// `list<float>` per row: `values` cut into rows of `width` values each.
    ListF32 {
        /// Every row's values, one row after the other.
        values: Vec<f32>,
        /// Values per row.
        width: usize,
    },
    /// `list<double>` per row, `width` values each.
    ListF64 {
        /// Every row's values, one row after the other.
        values: Vec<f64>,
        /// Values per row.
        width: usize,
    },
    /// `list<int64>` per row, `width` values each.
    ListI64 {
        /// Every row's values, one row after the other.
        values: Vec<i64>,
        /// Values per row.
        width: usize,
    },
    /// `list<string>` per row, `width` values each.
    ListStr {
        /// Every row's values, one row after the other.
        values: Vec<String>,
        /// Values per row.
        width: usize,
    },
}

impl Column {
    /// Number of rows.
    pub fn rows(&self) -> usize {
        match self {
            Self::F32(v) => v.len(),
            Self::F64(v) => v.len(),
            Self::I64(v) => v.len(),
            Self::Str(v) => v.len(),
            Self::ListF32 { values, width } => values.len() / (*width).max(1),
            Self::ListF64 { values, width } => values.len() / (*width).max(1),
            Self::ListI64 { values, width } => values.len() / (*width).max(1),
            Self::ListStr { values, width } => values.len() / (*width).max(1),
        }
    }

    fn schema(&self, name: &str) -> parquet::errors::Result<TypePtr> {
        let (physical, logical, list) = match self {
            Self::F32(_) => (Physical::FLOAT, None, false),
            Self::F64(_) => (Physical::DOUBLE, None, false),
            Self::I64(_) => (Physical::INT64, None, false),
            Self::Str(_) => (Physical::BYTE_ARRAY, Some(LogicalType::String), false),
            Self::ListF32 { .. } => (Physical::FLOAT, None, true),
            Self::ListF64 { .. } => (Physical::DOUBLE, None, true),
            Self::ListI64 { .. } => (Physical::INT64, None, true),
            Self::ListStr { .. } => (Physical::BYTE_ARRAY, Some(LogicalType::String), true),
        };
        let leaf = |n: &str| {
            Type::primitive_type_builder(n, physical)
                .with_repetition(Repetition::OPTIONAL)
                .with_logical_type(logical.clone())
                .build()
        };
        if !list {
            return Ok(Arc::new(leaf(name)?));
        }
        let element = Arc::new(leaf("element")?);
        let repeated = Type::group_type_builder("list")
            .with_repetition(Repetition::REPEATED)
            .with_fields(vec![element])
            .build()?;
        Ok(Arc::new(
            Type::group_type_builder(name)
                .with_repetition(Repetition::OPTIONAL)
                .with_logical_type(Some(LogicalType::List))
                .with_fields(vec![Arc::new(repeated)])
                .build()?,
        ))
    }
}

/// Named columns of equal length: one row group.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Table {
    /// Column names and values, in schema order.
    pub columns: Vec<(String, Column)>,
}

impl Table {
    /// Appends a column.
    pub fn push(&mut self, name: &str, column: Column) {
        self.columns.push((name.to_string(), column));
    }

    /// Number of rows (of the first column).
    pub fn rows(&self) -> usize {
        self.columns.first().map_or(0, |(_, c)| c.rows())
    }

    fn schema(&self) -> parquet::errors::Result<TypePtr> {
        let fields = self
            .columns
            .iter()
            .map(|(n, c)| c.schema(n))
            .collect::<parquet::errors::Result<Vec<_>>>()?;
        Ok(Arc::new(
            Type::group_type_builder("schema").with_fields(fields).build()?,
        ))
    }
}

/// A Parquet file being written one row group at a time; every row group has the schema of
/// the first.
pub struct ParquetFile {
    writer: SerializedFileWriter<File>,
}

impl ParquetFile {
    /// Starts a file with the schema of `first` (whose rows are not written yet) and the
    /// key–value metadata `meta` (e.g. `huggingface`, `pandas`).
    pub fn create(file: File, first: &Table, meta: Vec<(String, String)>) -> parquet::errors::Result<Self> {
        let kv = meta
            .into_iter()
            .map(|(k, v)| KeyValue::new(k, v))
            .collect::<Vec<_>>();
        let props = WriterProperties::builder()
            .set_compression(Compression::SNAPPY)
            .set_created_by(format!("macrotree {}", env!("CARGO_PKG_VERSION")))
            .set_key_value_metadata((!kv.is_empty()).then_some(kv))
            .build();
        let writer = SerializedFileWriter::new(file, first.schema()?, Arc::new(props))?;
        Ok(Self { writer })
    }

    /// Writes `table` as one row group.
    pub fn write(&mut self, table: &Table) -> parquet::errors::Result<()> {
        let mut rg = self.writer.next_row_group()?;
        for (_, column) in &table.columns {
            let mut col = rg.next_column()?.ok_or_else(|| {
                parquet::errors::ParquetError::General("more columns than the schema".into())
            })?;
            write_column(&mut col, column)?;
            col.close()?;
        }
        rg.close()?;
        Ok(())
    }

    /// Finishes the file (writes its footer) and returns it.
    pub fn finish(self) -> parquet::errors::Result<File> {
        self.writer.into_inner()
    }
}

/// Definition and repetition levels of `rows` lists of `width` present values each.
fn list_levels(rows: usize, width: usize) -> (Vec<i16>, Vec<i16>) {
    let mut def = Vec::with_capacity(rows * width.max(1));
    let mut rep = Vec::with_capacity(rows * width.max(1));
    for _ in 0..rows {
        if width == 0 {
            // An empty (not null) list: the list is defined, no element.
            def.push(1);
            rep.push(0);
        }
        for i in 0..width {
            def.push(3);
            rep.push(if i == 0 { 0 } else { 1 });
        }
    }
    (def, rep)
}

fn write_column(
    col: &mut parquet::file::writer::SerializedColumnWriter<'_>,
    column: &Column,
) -> parquet::errors::Result<()> {
    let strings = |v: &[String]| v.iter().map(|s| ByteArray::from(s.as_str())).collect::<Vec<_>>();
    match column {
        Column::F32(v) => {
            col.typed::<FloatType>()
                .write_batch(v, Some(&vec![1; v.len()]), None)?;
        }
        Column::F64(v) => {
            col.typed::<DoubleType>()
                .write_batch(v, Some(&vec![1; v.len()]), None)?;
        }
        Column::I64(v) => {
            col.typed::<Int64Type>()
                .write_batch(v, Some(&vec![1; v.len()]), None)?;
        }
        Column::Str(v) => {
            col.typed::<ByteArrayType>()
                .write_batch(&strings(v), Some(&vec![1; v.len()]), None)?;
        }
        Column::ListF32 { values, width } => {
            let (d, r) = list_levels(column.rows(), *width);
            col.typed::<FloatType>().write_batch(values, Some(&d), Some(&r))?;
        }
        Column::ListF64 { values, width } => {
            let (d, r) = list_levels(column.rows(), *width);
            col.typed::<DoubleType>()
                .write_batch(values, Some(&d), Some(&r))?;
        }
        Column::ListI64 { values, width } => {
            let (d, r) = list_levels(column.rows(), *width);
            col.typed::<Int64Type>().write_batch(values, Some(&d), Some(&r))?;
        }
        Column::ListStr { values, width } => {
            let (d, r) = list_levels(column.rows(), *width);
            col.typed::<ByteArrayType>()
                .write_batch(&strings(values), Some(&d), Some(&r))?;
        }
    }
    Ok(())
}
