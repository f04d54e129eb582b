# fogdrift export --target gnss-ins-sim: noise model for gnss-ins-sim imu_err dictionary (README 'Step 1.1'; imu_model.IMU)
# from out/adis16405_imu1/allan.json (input SHA-256 a04609489001939e...)
# update rate 100.0 Hz; --missing bound
# gyro gx: allan model N+B+S+M (chi2_red 1.59, good)
# gyro gy: allan model N+B+K (chi2_red 1.55, good)
# gyro gz: allan no model fits; best candidate Q+N+B+K+S (chi2_red 6.12, poor)
# continuous -> discrete: white sigma_d = N sqrt(f), random-walk step sigma_bd = K / sqrt(f) (Kalibr wiki 'IMU Noise Model')
# b_stability is the 1-sigma of a first-order Gauss-Markov bias with correlation time b_corr (gnss-ins-sim's bias_drift)
import numpy as np

imu_err = {
    # constant bias: not a noise term (removed by calibration); 0 = a calibrated sensor
    'gyro_b': np.array([0.0, 0.0, 0.0]),  # [deg/h]
    # gx: N = 2.402 [2.374, 2.417] deg/sqrt(h) [resolved]; from allan fit: N (selected model N+B+S+M, fit good)
    #   continuous 0.000698605 rad/s/sqrt(Hz) (the estimate; x 0.000290888 (deg/sqrt(h) -> rad/s/sqrt(Hz))); discrete 0.00698605 rad/s per sample at 100.0 Hz (x sqrt(f))
    # gy: N = 2.521 [2.501, 2.537] deg/sqrt(h) [resolved]; from allan fit: N (selected model N+B+K, fit good)
    #   continuous 0.000733391 rad/s/sqrt(Hz) (the estimate; x 0.000290888 (deg/sqrt(h) -> rad/s/sqrt(Hz))); discrete 0.00733391 rad/s per sample at 100.0 Hz (x sqrt(f))
    # gz: N = 2.228 [2.157, 2.306] deg/sqrt(h) [no_fit]; from allan fit: N (selected model Q+N+B+K+S, fit poor)
    #   continuous 0.000670925 rad/s/sqrt(Hz) (its 95 % upper bound (--missing bound); x 0.000290888 (deg/sqrt(h) -> rad/s/sqrt(Hz))); discrete 0.00670925 rad/s per sample at 100.0 Hz (x sqrt(f))
    # written per axis (gx, gy, gz) in deg/sqrt(h)
    'gyro_arw': np.array([2.40163, 2.52121, 2.30647]),  # [deg/sqrt(h)]
    # gx: bias Gauss-Markov: one GM matched to B (estimate): sigma = 1.0760 B, T_c = tau_B/1.8926 with tau_B = 1311 s (its Allan peak equals the flicker floor 0.664 B there)
    #   sigma = 0.000128063 rad/s (95 % [13.9759, 38.5606] deg/h), T_c = 692.543 s; discrete at 100.0 Hz: phi = exp(-dt/T_c) = 0.999985561, driving sigma = sigma sqrt(1 - phi^2) = 6.88197e-07 rad/s
    # gy: bias Gauss-Markov: one GM matched to B (estimate): sigma = 1.0760 B, T_c = tau_B/1.8926 with tau_B = 119.6 s (its Allan peak equals the flicker floor 0.664 B there)
    #   sigma = 0.000189436 rad/s (95 % [31.3455, 47.0753] deg/h), T_c = 63.212 s; discrete at 100.0 Hz: phi = exp(-dt/T_c) = 0.999841815, driving sigma = sigma sqrt(1 - phi^2) = 3.36933e-06 rad/s
    # gz: bias Gauss-Markov: one GM matched to B (bound: B is its 95 % upper bound 44.91 deg/h, not an estimate (--missing bound): no model fits the record (best candidate Q+N+B+K+S, chi2_red 6.12): the coefficient is no result; not resolved from zero: its 95 % interval reaches 0): sigma = 1.0760 B, T_c = tau_B/1.8926 with tau_B = 72.79 s (its Allan peak equals the flicker floor 0.664 B there)
    #   sigma = 0.00023429 rad/s, T_c = 38.4613 s; discrete at 100.0 Hz: phi = exp(-dt/T_c) = 0.999740032, driving sigma = sigma sqrt(1 - phi^2) = 5.34195e-06 rad/s
    # written per axis: sigma in deg/h, T_c in s
    'gyro_b_stability': np.array([26.4149, 39.074, 48.3257]),  # [deg/h]
    'gyro_b_corr': np.array([692.543, 63.212, 38.4613]),  # [s]
    # accel_b, accel_vrw, accel_b_stability, accel_b_corr: not written: no accelerometer result was given (fogdrift export --accel RESULT.json); fogdrift never writes a noise figure it did not measure
}
