# fogdrift export --target gnss-ins-sim: noise model for gnss-ins-sim imu_err dictionary (README 'Step 1.1'; imu_model.IMU)
# from out/adis16405_imu1/allan.json (input SHA-256 a04609489001939e...)
# update rate 100.0 Hz; --missing bound
# gyro gx: allan model N+B+M (chi2_red 0.555, good)
# gyro gy: allan model N+B+K (chi2_red 0.329, good)
# gyro gz: allan model N+B+K (chi2_red 0.738, good)
# continuous -> discrete: white sigma_d = N sqrt(f), random-walk step sigma_bd = K / sqrt(f) (Kalibr wiki 'IMU Noise Model')
# gnss_ins_sim/sim/imu_model.py IMU(accuracy=imu_err) requires gyro_b, gyro_b_stability, gyro_arw, accel_b, accel_b_stability, accel_vrw (b_corr optional: infinite = white bias); pathgen.py applies arw and
# vrw as continuous densities (per sample / sqrt(dt)); b_stability is the 1-sigma of a first-order Gauss-Markov bias with correlation time b_corr (bias_drift)
import numpy as np

imu_err = {
    # constant bias: not a noise term (removed by calibration); 0 = a calibrated sensor
    'gyro_b': np.array([0.0, 0.0, 0.0]),  # [deg/h]
    # gx: N = 2.425 [2.308, 2.513] deg/sqrt(h) [resolved]; from allan fit: N (selected model N+B+M, fit good)
    #   continuous 0.000705481 rad/s/sqrt(Hz) (the estimate; x 0.000290888 (deg/sqrt(h) -> rad/s/sqrt(Hz))); discrete 0.00705481 rad/s per sample at 100.0 Hz (x sqrt(f))
    # gy: N = 2.539 [2.439, 2.613] deg/sqrt(h) [resolved]; from allan fit: N (selected model N+B+K, fit good)
    #   continuous 0.000738681 rad/s/sqrt(Hz) (the estimate; x 0.000290888 (deg/sqrt(h) -> rad/s/sqrt(Hz))); discrete 0.00738681 rad/s per sample at 100.0 Hz (x sqrt(f))
    # gz: N = 2.296 [2.188, 2.361] deg/sqrt(h) [resolved]; from allan fit: N (selected model N+B+K, fit good)
    #   continuous 0.000667988 rad/s/sqrt(Hz) (the estimate; x 0.000290888 (deg/sqrt(h) -> rad/s/sqrt(Hz))); discrete 0.00667988 rad/s per sample at 100.0 Hz (x sqrt(f))
    # written per axis (gx, gy, gz) in deg/sqrt(h)
    'gyro_arw': np.array([2.42526, 2.5394, 2.29637]),  # [deg/sqrt(h)] continuous time
    # gx: bias Gauss-Markov: one GM matched to B (estimate: B = 20.33 deg/h is the estimate, not resolved from zero: the model N+M without B describes the curve about as well (IC +1.5)): sigma = 1.0760 B, T_c = tau_B/1.8926 with tau_B = 1311 s (its Allan peak equals the flicker floor 0.664 B there)
    #   sigma = 0.000106076 rad/s (95 % [0.0, 38.7081] deg/h), T_c = 692.543 s; discrete at 100.0 Hz: phi = exp(-dt/T_c) = 0.999985561, driving sigma = sigma sqrt(1 - phi^2) = 5.70039e-07 rad/s
    # gy: bias Gauss-Markov: one GM matched to B (estimate): sigma = 1.0760 B, T_c = tau_B/1.8926 with tau_B = 111.8 s (its Allan peak equals the flicker floor 0.664 B there)
    #   sigma = 0.000177729 rad/s (95 % [27.9646, 46.2147] deg/h), T_c = 59.0712 s; discrete at 100.0 Hz: phi = exp(-dt/T_c) = 0.999830727, driving sigma = sigma sqrt(1 - phi^2) = 3.27001e-06 rad/s
    # gz: bias Gauss-Markov: one GM matched to B (estimate): sigma = 1.0760 B, T_c = tau_B/1.8926 with tau_B = 69.58 s (its Allan peak equals the flicker floor 0.664 B there)
    #   sigma = 0.000133157 rad/s (95 % [15.2155, 37.8311] deg/h), T_c = 36.7627 s; discrete at 100.0 Hz: phi = exp(-dt/T_c) = 0.999728022, driving sigma = sigma sqrt(1 - phi^2) = 3.10539e-06 rad/s
    # written per axis: sigma in deg/h, T_c in s
    'gyro_b_stability': np.array([21.8797, 36.6593, 27.4656]),  # [deg/h]
    'gyro_b_corr': np.array([692.543, 59.0712, 36.7627]),  # [s]
    # constant bias: not a noise term (removed by calibration); 0 = a calibrated sensor
    'accel_b': np.array([0.0, 0.0, 0.0]),  # [m/s^2]
    # accel_vrw, accel_b_stability, accel_b_corr: NOT MEASURED: no accelerometer result was given (fogdrift export --accel RESULT.json); the program requires them, so gnss-ins-sim's default profile 'low-accuracy' (gnss_ins_sim/sim/imu_model.py) values are written: replace them with your accelerometer's
    'accel_vrw': np.array([0.05, 0.05, 0.05]),  # [m/s/sqrt(h)] NOT MEASURED
    'accel_b_stability': np.array([0.0002, 0.0002, 0.0002]),  # [m/s^2] NOT MEASURED
    'accel_b_corr': np.array([100.0, 100.0, 100.0]),  # [s] NOT MEASURED
}
