"""The papers' data: every table, geometry and published result that refsph uses, transcribed once (SI units
unless the key says otherwise). Scenes, tests and chapters take their numbers from here and nowhere else.

Sources: Islam, Bansal & Peng, "Numerical Simulation of Metal Machining Process with Eulerian and Total
Lagrangian SPH" (Sections 3.1-3.3, Tables 1-5; the Taylor experiment is House et al. 1995, the paper's ref. [44];
the LS-DYNA numbers are its ref. [42]); Rodriguez Prieto, Larsson & Afrasiabi (Tables 1-2). Copied into the
package so that nothing reads files outside it at run time. (Named for what it is: "reference" means the
reference configuration in TLSPH.)
"""
from __future__ import annotations

__all__ = ["TAYLOR_TABLE1", "TAYLOR_TABLE2", "TAYLOR_GEOMETRY", "TAYLOR_RESULTS", "AISI4340_TABLE3",
           "PRESSING_TABLE4", "PRESSING_GEOMETRY", "PRESSING_RESOLUTIONS_M", "CUTTING_TABLE5", "CUTTING_GEOMETRY",
           "CUTTING_OBSERVED", "AISI1045_RLA", "TI6AL4V_RLA", "TOOL_CARBIDE_RLA", "CONTACT_RLA", "RLA_SURFACE_LOSS",
           "RLA_CUTTING_COLUMNS",
           "RLA_CUTTING_CASES", "rla_cutting_case"]

# Table 1: Johnson-Cook parameters of low-strength 4340 steel, as printed (T_m = 1293 K; 1793 K is usual)
TAYLOR_TABLE1 = dict(rho=7830.0, shear_modulus_Pa=82.9e9, bulk_modulus_Pa=169.1e9, A_Pa=792e6, B_Pa=510e6,
                     n=0.26, C=0.014, m=1.03, T_room_K=293.0, T_melt_K=1293.0, cp_J_kgK=460.0,
                     taylor_quinney=0.9)
# Table 2: computational parameters
TAYLOR_TABLE2 = dict(particle_spacing_m=0.5e-3, smoothing_length_m=0.75e-3, time_step_s=1e-8,
                     beta1=1.5, beta2=1.5, artificial_pressure_gamma_esph=0.3)
# Section 3.1: the bar and the wall
TAYLOR_GEOMETRY = dict(length_m=37.97e-3, diameter_m=7.595e-3, impact_velocity_m_s=181.0,
                       wall="rigid, frictionless")
# Section 3.1: final length and mushroom diameter [mm]
TAYLOR_RESULTS = {
    "final_length_mm": {"experiment": 34.6, "ls_dyna": 34.4, "paper_esph": 34.19, "paper_tlsph": 34.18},
    "final_diameter_mm": {"experiment": 9.5, "ls_dyna": 10.6, "paper_esph": 9.80, "paper_tlsph": 9.83},
}

# Table 3: Johnson-Cook parameters of the AISI 4340 workpiece (pressing and cutting), as printed. The
# Taylor-Quinney coefficient chi = 0.9 is stated in Section 2.3 (Eq. (28)), not in the table.
AISI4340_TABLE3 = dict(rho=7830.0, E_Pa=207e9, nu=0.3, A_Pa=792e6, B_Pa=510e6, n=0.26, C=0.014, m=1.03,
                       T_room_K=298.0, T_melt_K=1573.0, cp_J_kgK=480.0, taylor_quinney=0.9)
# Table 4: computational parameters of the pressing (h / dp = 1.5)
PRESSING_TABLE4 = dict(particle_spacing_m=0.00667e-3, smoothing_length_m=0.01e-3, time_step_s=1e-10,
                       beta1=0.5, beta2=0.5, artificial_pressure_gamma_esph=0.3)
# Section 3.2: a block 1.0 x 0.5 (x 0.1) mm, left side fixed, a rigid tool 0.1 x 0.7 (x 0.1) mm pressed from
# the free right side at 200 m/s. The paper's 3D run used 184,624 workpiece and 25,199 tool particles.
PRESSING_GEOMETRY = dict(block_m=(1.0e-3, 0.5e-3), tool_m=(0.1e-3, 0.7e-3), tool_speed_m_s=200.0,
                         thickness_3d_m=0.1e-3)
# Section 3.2, Fig. 10: the resolution study (h / dp = 1.5 kept); 0.0167 = 1/60 mm, 0.0133 = 1/75 mm, ...
PRESSING_RESOLUTIONS_M = (0.0167e-3, 0.0133e-3, 0.01e-3, 0.00667e-3)
# Section 3.3 and Table 5: orthogonal cutting (2D plane strain; h / dp = 1.8)
CUTTING_TABLE5 = dict(particle_spacing_m=0.01e-3, smoothing_length_m=0.018e-3, time_step_s=1e-10,
                      beta1=0.5, beta2=0.5, artificial_pressure_gamma_esph=0.3)
# Section 3.3: a workpiece 3 x 1 mm, a rigid tool 0.5 x 1 mm moving at 50 m/s, feeds ("feeding length") 0.3 and
# 0.5 mm
CUTTING_GEOMETRY = dict(workpiece_m=(3.0e-3, 1.0e-3), tool_m=(0.5e-3, 1.0e-3), tool_speed_m_s=50.0,
                        feeds_m=(0.3e-3, 0.5e-3))
# Section 3.3.1-3.3.2: what the paper reports for the cutting, in words only (no numbers are printed besides
# the band angle): bands from the tool tip to the free surface at about 45 deg; a deeper feed gives a larger
# cutting force and fewer, wider-spaced shear bands (larger chip segments).
CUTTING_OBSERVED = dict(band_angle_deg=45.0, deeper_feed="larger cutting force, fewer and wider-spaced bands")

# Rodriguez Prieto, Larsson & Afrasiabi, "Thermomechanical Simulation of Orthogonal Metal Cutting with PFEM and
# SPH Using a Temperature-Dependent Friction Coefficient", Tables 1-2: AISI 1045 with the *modified*
# Johnson-Cook law (hardening stops growing past plastic strain 2, their Eqs. (8)-(9)). Room temperature 293 K
# (their contact data), chi = 0.9. Their Table 2 prints "0.812.09" for mu0 and q: read as 0.81 and 2.09.
AISI1045_RLA = dict(rho=7870.0, E_Pa=205e9, nu=0.29, k_W_mK=50.7, cp_J_kgK=486.0, T_melt_K=1773.0,
                    T_room_K=293.0, A_Pa=288e6, B_Pa=695e6, C=0.0340, m=1.3558, n=0.2835, eps_dot_0=0.004,
                    hardening_saturation_strain=2.0, taylor_quinney=0.9, mu0=0.81, q_friction=2.09)

# Rodriguez Prieto, Larsson & Afrasiabi, Table 2 (Ti6Al4V) and Table 1 (the carbide tool), Appendix B (the 18
# orthogonal cuts: rake 10 deg, clearance 10 deg, edge radius 10 um). The measured values (*_exp) are not printed:
# they were recovered from each printed prediction and its printed percent error (PFEM and SPH give the same
# value to < 0.1 %, except case 3: 5 %). Forces in N as printed (the width of cut is not stated), temperatures in K:
# T_RF on the rake face, T_FCS on the free chip surface. Transcribed from the project's reference data
# (shared/reference/rodriguez-larsson-afrasiabi-*.{toml,csv}).
TI6AL4V_RLA = dict(rho=4430.0, E_Pa=110e9, nu=0.342, k_W_mK=7.44, cp_J_kgK=553.0, T_melt_K=1877.0, T_room_K=293.0,
                   A_Pa=940e6, B_Pa=965e6, C=0.0387, m=0.9835, n=0.8372, eps_dot_0=0.004, taylor_quinney=0.9,
                   mu0=0.51, q_friction=5.76)
# the tool: rigid mechanically, conducting heat; cp as printed (15 J/(kg K): a reduced heat capacity, so that the
# tool reaches its steady temperature within the short simulated cut)
TOOL_CARBIDE_RLA = dict(rho=15700.0, E_Pa=600e9, nu=0.2, k_W_mK=59.0, cp_J_kgK=15.0)
# Not printed by the paper: the convection coefficient and emissivity of their Eq. (6). refsph takes h_c = 20
# W/(m^2 K) (free convection in air, the usual default of cutting codes) and emissivity 0.3 (bright machined steel);
# over a few ms of cut these losses are below 1e-3 of the heat made (benchmarks/thermal_cutting.json, heat balance).
RLA_SURFACE_LOSS = dict(h_c=20.0, emissivity=0.3)
CONTACT_RLA = dict(T_ref_K=293.0, plastic_work_to_heat=0.9, friction_work_to_heat=1.0)
RLA_CUTTING_COLUMNS = ("case", "material", "vc_m_per_min", "tu_mm", "Fc_exp_N", "Fp_exp_N", "TRF_exp_K", "TFCS_exp_K",
                       "Fc_sph_N", "Fp_sph_N", "TRF_sph_K", "TFCS_sph_K", "Fc_pfem_N", "Fp_pfem_N", "TRF_pfem_K",
                       "TFCS_pfem_K")
RLA_CUTTING_CASES = (
    (1, "AISI1045", 60.0, 0.1, 622.0, 489.0, 668.0, 647.0,
     703.54, 323.85, 671.5, 522.08, 499.73, 311.35, 850.0, 643.0),
    (2, "AISI1045", 60.0, 0.15, 833.0, 637.0, 730.0, 639.0,
     967.55, 418.72, 659.18, 509.08, 689.69, 427.6, 863.0, 646.0),
    (3, "AISI1045", 60.0, 0.2, 1022.0, 802.0, 715.0, 643.0,
     1191.91, 492.56, 618.31, 476.13, 843.01, 492.79, 880.0, 660.0),
    (4, "AISI1045", 120.0, 0.1, 492.0, 404.0, 795.0, 671.0,
     717.6, 342.5, 743.82, 534.79, 407.62, 210.91, 1008.0, 668.0),
    (5, "AISI1045", 120.0, 0.15, 735.0, 557.0, 893.0, 657.0,
     958.99, 422.12, 728.02, 513.68, 590.68, 323.79, 1017.0, 667.0),
    (6, "AISI1045", 120.0, 0.2, 944.0, 670.0, 995.0, 649.0,
     1217.72, 498.55, 676.39, 487.28, 788.58, 470.89, 1025.0, 680.0),
    (7, "AISI1045", 180.0, 0.1, 526.0, 436.0, 925.0, 678.0,
     661.76, 285.42, 796.5, 532.21, 350.48, 152.76, 1050.0, 710.0),
    (8, "AISI1045", 180.0, 0.15, 746.0, 530.0, 1031.0, 658.0,
     965.0, 424.38, 798.56, 546.06, 517.79, 224.6, 1080.0, 712.0),
    (9, "AISI1045", 180.0, 0.2, 900.0, 583.0, 1102.0, 658.0,
     1222.5, 507.84, 725.65, 493.09, 696.91, 322.72, 1120.0, 714.0),
    (10, "Ti6Al4V", 20.0, 0.1, 597.0, 303.0, 701.0, 711.0,
     678.79, 250.46, 1289.11, 801.86, 383.24, 164.62, 900.0, 880.0),
    (11, "Ti6Al4V", 20.0, 0.15, 629.0, 356.0, 690.0, 687.0,
     1027.53, 398.65, 1376.49, 774.27, 535.51, 223.84, 953.0, 926.0),
    (12, "Ti6Al4V", 20.0, 0.2, 748.0, 339.0, 771.0, 667.0,
     1319.81, 494.79, 1334.2, 747.94, 624.17, 228.18, 1120.0, 940.0),
    (13, "Ti6Al4V", 40.0, 0.1, 434.0, 256.0, 783.0, 688.0,
     550.84, 156.25, 1316.03, 777.58, 352.62, 169.89, 1150.0, 955.0),
    (14, "Ti6Al4V", 40.0, 0.15, 602.0, 337.0, 873.0, 665.0,
     883.82, 255.02, 1361.25, 767.15, 482.86, 213.44, 1250.0, 950.0),
    (15, "Ti6Al4V", 40.0, 0.2, 728.0, 367.0, 900.0, 668.0,
     1155.34, 391.25, 1399.15, 772.01, 623.92, 263.25, 1260.0, 961.0),
    (16, "Ti6Al4V", 60.0, 0.1, 412.0, 259.0, 918.0, 692.0,
     528.64, 119.94, 1303.87, 792.86, 337.0, 155.6, 1280.0, 975.0),
    (17, "Ti6Al4V", 60.0, 0.15, 581.0, 336.0, 965.0, 690.0,
     800.95, 179.74, 1350.74, 787.08, 464.26, 189.02, 1350.0, 983.0),
    (18, "Ti6Al4V", 60.0, 0.2, 680.0, 346.0, 998.0, 728.0,
     1011.86, 185.78, 1334.11, 762.14, 608.0, 240.14, 1400.0, 990.0),
)


def rla_cutting_case(case: int) -> dict:
    """Row ``case`` (1-18) of the second paper's Appendix B as a dict of RLA_CUTTING_COLUMNS."""
    if not 1 <= int(case) <= len(RLA_CUTTING_CASES):
        raise ValueError(f"case must be 1..{len(RLA_CUTTING_CASES)}, got {case!r}")
    return dict(zip(RLA_CUTTING_COLUMNS, RLA_CUTTING_CASES[int(case) - 1]))
