//! Tests of the `physics` layer's modules.

mod contact_jkr;
mod contact_lj_kernel;
mod contact_lj_moving;
mod contact_lj_solver;
mod contact_viscoelastic;
mod law;
mod law_adhesive;
mod law_capillary;
mod law_fold_branch;
mod law_reversible;
mod law_rigid;
mod law_sls;
mod law_table;
mod law_viscous;
mod params;
