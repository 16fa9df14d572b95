//! Population Monte Carlo for rendering (paper 003): the `mis` baseline, PMC-HI (§5) with its
//! feedback variant (§6.1), and the image-plane samplers (§4).

pub mod ceiling;
pub mod hi;
pub mod ip;
pub mod kernel;
pub mod mis;
pub mod sub_images;
pub mod threshold_image;
pub mod uniform_image;

#[cfg(test)]
mod stability_tests;
#[cfg(test)]
mod tests;
