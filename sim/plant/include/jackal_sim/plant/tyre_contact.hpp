#pragma once
/**
 * \file tyre_contact.hpp
 * \brief The wheel-ground force law of the "slip" friction model: an isotropic brush tyre
 *        whose friction force follows the wheel's slip (sliding velocity over the wheel's
 *        speed), saturating at mu N, and its mapping onto ODE's force-dependent slip.
 *
 * ROS-free, no ODE types. Used by Plant (contact.friction_model "slip").
 *
 * Slip. For one wheel, with its centre's ground velocity split into v_x (along the rolling
 * direction) and v_y (along the axle), the rolling speed v_r = r |omega| of its spin, and the
 * contact point's sliding velocity v_s (tangential part of the velocity of the tyre's material
 * at the contact over the ground: (v_x - r omega, v_y)), the combined slip is
 *
 *     sigma = |v_s| / V,   V = max(|v_x|, v_r, v_min)
 *
 * which is the slip ratio (r omega - v_x) / max(|v_x|, r|omega|) when the wheel slides only along
 * its rolling direction and tan(alpha) = v_y / |v_x| (alpha the slip angle) when it only slides
 * sideways at a free-rolling speed: the "practical" slip quantities of tyre mechanics (H.B.
 * Pacejka, *Tire and Vehicle Dynamics*, 3rd ed., Butterworth-Heinemann 2012, section 1.2 and
 * chapter 3), with the larger of the two speeds as the reference so that the slip stays finite
 * when a wheel spins at rest or is dragged locked (E. Bakker, L. Nyborg, H.B. Pacejka, SAE paper
 * 870421, 1987; the denominator of Dugoff et al.'s slip, H. Dugoff, P.S. Fancher, L. Segel,
 * SAE paper 700377, 1970). v_min (> 0) keeps the law defined at rest: below it the force follows
 * the sliding speed, as a tyre's compliance does.
 *
 * Force. The isotropic brush model with a parabolic pressure distribution (Pacejka 2012,
 * section 3.2.3, combined slip with equal longitudinal and lateral tread stiffness): the force
 * opposes the sliding velocity and its magnitude over the normal load is
 *
 *     F / N = mu (3 t - 3 t^2 + t^3),  t = C sigma / (3 mu),   for t < 1
 *     F / N = mu,                                              for t >= 1 (full sliding)
 *
 * with C the slip stiffness over the normal load (the initial slope dF/dsigma / N, the same for
 * cornering and for longitudinal slip in the isotropic brush model). It rises linearly with
 * slope C, saturates smoothly and reaches mu N at sigma = 3 mu / C. With C -> infinity it is
 * Coulomb friction (the "cone" model), whose force is mu N at any sliding speed.
 *
 * What it does to a skid-steer robot (J.L. Mandow et al., "Experimental kinematics for wheeled
 * skid-steer mobile robots", IROS 2007): turning in place every wheel slides at a slip of
 * ~0.5, far beyond 3 mu / C, so the contact is Coulomb's and the robot turns with the effective
 * separation track + wheelbase^2 / track; on an arc of radius R the wheels' slips fall as
 * ~wheelbase / (2 R), so the scrub force, and the torque the motors need to turn, falls as the
 * radius grows (measured on skid-steer robots: W. Yu, O. Chuy, E.G. Collins, P. Hollis,
 * "Analysis and experimental verification for dynamic modeling of a skid-steered wheeled
 * vehicle", IEEE Trans. Robotics 26(2), 2010). Gazebo's WheelSlipPlugin rests on the same idea
 * (ODE's slip set to a unitless compliance times the wheel's speed over its normal force: a linear
 * law in slip up to mu N).
 *
 * ODE. ODE's force-dependent slip s [m/(s N)] makes a friction row a damper: F = v_s / s, capped
 * at mu N by the friction pyramid. odeSlip() returns the secant s = |v_s| / F(sigma) at the
 * current slip, so that ODE's (implicit) friction force equals the brush force at the sliding
 * velocity the step starts from, and the linear law's V / (C N) when the wheel hardly slides;
 * beyond full sliding (sigma >= 3 mu / C) the secant at 3 mu / C along the sliding, whose damper
 * force exceeds mu N, so that the friction pyramid's cap gives Coulomb's mu N; across the sliding
 * V / (C N) at any slip (odeSlip()).
 */

namespace jackal_aic
{
namespace plant
{
/**
 * \brief The brush tyre's friction force over the normal load at a combined slip.
 * \param slip      combined slip sigma = |v_s| / V [-], >= 0 (negative values are taken as 0)
 * \param stiffness slip stiffness C over the normal load [-] (1 / unit slip), > 0
 * \param mu        friction coefficient [-], >= 0
 * \return F / N in [0, mu]: mu (3t - 3t^2 + t^3) with t = C slip / (3 mu), mu once t >= 1; 0 if
 *         mu is 0. Non-finite or non-positive stiffness returns mu (Coulomb).
 */
double brushForceRatio(double slip, double stiffness, double mu);

/// The slip state of one wheel contact (all speeds in the ground plane, [m/s]).
struct WheelSlip
{
  double reference_speed = 0.0;  ///< V = max(|v_x|, r |omega|, v_min) [m/s]
  double sliding_speed = 0.0;    ///< |v_s| [m/s]
  double slip = 0.0;             ///< sigma = |v_s| / V [-]
};

/**
 * \brief The combined slip of a wheel.
 * \param forward_speed  v_x: the wheel centre's ground velocity along the rolling direction [m/s]
 * \param rolling_speed  r omega: the wheel's spin times its radius [m/s] (sign ignored)
 * \param sliding_speed  |v_s|: the speed at which the tyre slides over the ground at the contact [m/s]
 * \param min_reference  v_min: the smallest reference speed [m/s], > 0
 * \throws std::invalid_argument unless min_reference > 0 and every input is finite
 */
WheelSlip wheelSlip(double forward_speed, double rolling_speed, double sliding_speed, double min_reference);

/// ODE's force-dependent slips [m/(s N)] of a contact whose fdir1 follows the sliding velocity.
struct OdeSlip
{
  double along = 0.0;   ///< slip1: along the sliding velocity (fdir1)
  double across = 0.0;  ///< slip2: across it (fdir2)
};

/**
 * \brief ODE's force-dependent slips [m/(s N)] for a wheel contact under the brush law, fdir1 along
 *        the sliding velocity.
 *
 * Along the sliding: the secant V sigma' / F(sigma'), F = brushForceRatio(sigma') N,
 * sigma' = min(sigma, 3 mu / C), so that ODE's damper gives the brush force below full sliding and
 * the friction pyramid's mu N cap gives Coulomb's force beyond it. Across: the law's slope at zero
 * slip, V / (C N), its stiffest, which keeps the sliding along fdir1 within the step (fdir1 is the
 * sliding direction at the start of the step; the isotropic law's own stiffness across a full
 * sliding, F / |v_s|, is softer, and with it the sliding direction lags a step behind fdir1 and the
 * wheels chatter). Both are V / (C N) (the linear law's) when sigma is ~0.
 * \param s          the wheel's slip state (wheelSlip())
 * \param stiffness  C [-], > 0
 * \param mu         friction coefficient [-], > 0
 * \param normal_load N [N], > 0 (the caller floors it)
 * \throws std::invalid_argument unless stiffness, mu and normal_load are > 0 and finite
 */
OdeSlip odeSlip(const WheelSlip& s, double stiffness, double mu, double normal_load);

}  // namespace plant
}  // namespace jackal_aic
