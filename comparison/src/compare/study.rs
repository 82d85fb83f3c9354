//! The 2018 study's published numbers (comparison/data/thesis-vk-vs-gl-results.csv,
//! seconds per render-loop iteration), so every report can put ours beside them.

const CSV: &str = include_str!("../../data/thesis-vk-vs-gl-results.csv");

#[derive(Debug, Clone)]
pub struct StudyRow {
    pub experiment: String,
    pub param_value: String,
    pub vulkan_mean_s: f64,
    pub vulkan_median_s: f64,
    pub opengl_mean_s: f64,
    pub opengl_median_s: f64,
}

pub fn rows() -> Vec<StudyRow> {
    CSV.lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
        .filter_map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            if f.len() != 7 {
                return None;
            }
            Some(StudyRow {
                experiment: f[0].to_string(),
                param_value: f[2].to_string(),
                vulkan_mean_s: f[3].parse().ok()?,
                vulkan_median_s: f[4].parse().ok()?,
                opengl_mean_s: f[5].parse().ok()?,
                opengl_median_s: f[6].parse().ok()?,
            })
        })
        .collect()
}

pub fn find<'a>(rows: &'a [StudyRow], experiment: &str, value: &str) -> Option<&'a StudyRow> {
    rows.iter()
        .find(|r| r.experiment == experiment && r.param_value == value)
}

#[cfg(test)]
mod tests {
    #[test]
    fn all_study_rows_parse() {
        let r = super::rows();
        assert_eq!(r.len(), 29, "10 teapot + 10 box + 9 spherelist");
        assert!(super::find(&r, "spherelist", "10000").is_some());
    }
}
