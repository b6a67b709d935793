//! The clustered PCA of Otsu, Yamamoto and Hachisuka 2018: a kd-tree on CIE xy whose leaves
//! hold a cluster's PCA. From the bottom up: [`tree`] (the nodes and the walk, Eq. 10),
//! [`pca`] (Eq. 5–8), [`train`] (greedy splitting, Eq. 10–13), [`model`] (the trained tree and
//! its file), [`gamut`] (where a model's real colours are), [`blend`] (continuity across split
//! lines), [`hard_inputs`] (colours that are not ordinary) and [`runtime`] (r = T·c + o); [`terms`] (the terms of use of training data).

pub mod blend;
pub mod gamut;
pub mod hard_inputs;
pub mod model;
pub mod pca;
pub mod runtime;
pub mod terms;
pub mod train;
pub mod tree;
