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
           "CUTTING_OBSERVED", "AISI1045_RLA"]

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
