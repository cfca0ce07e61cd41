// livo-evaluate against evo on the shared trajectory pairs (../shared/data/trajectories).
//
// The reference numbers were produced by evo v1.36.5 (github MichaelGrupp/evo, commit
// 26d0953d4da0f0cb56f90ba6269a15e72f69d3ad, the commit the shared trajectories come from), run
// from its source with Debian 12's python3 3.11.2, numpy 1.24.2 and scipy 1.10.1, with the command
// written above each row (`--save_results`, statistics read at full precision from stats.json).
// evo's defaults apply: association max. 0.01 s (TUM pairs), KITTI pairs by index.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <string>

#include "livo/evaluate/evaluation.hpp"

using namespace livo;
using namespace livo::evaluate;

namespace {

const std::string kTrajectories = std::string(LIVO_SHARED_DATA) + "/trajectories/";

enum Metric { kAte, kRpeTranslation, kRpeRotation };

struct EvoReference {
  const char* gt;
  const char* est;
  const char* align;
  Metric metric;
  int delta;
  bool all_pairs;
  size_t count;
  double rmse, mean, median, std, min, max;
};

const EvoReference kEvo[] = {
    // evo_ape kitti KITTI_00_gt.txt KITTI_00_ORB.txt -a
    {"KITTI_00_gt.txt", "KITTI_00_ORB.txt", "se3", kAte, 1, false, 4541, 1.3034497145650565, 1.1569971285390057,
     1.0656247695558581, 0.60028226939684193, 0.069313220214813412, 3.5879491206789789},
    // evo_rpe kitti KITTI_00_gt.txt KITTI_00_ORB.txt -a --pose_relation trans_part --delta 1 --delta_unit f
    {"KITTI_00_gt.txt", "KITTI_00_ORB.txt", "se3", kRpeTranslation, 1, false, 4540, 0.0281203770173938,
     0.019301310981393743, 0.014709043438551155, 0.020450305572286661, 0.00031240026311805046, 0.30271249059533634},
    // evo_rpe kitti KITTI_00_gt.txt KITTI_00_ORB.txt -a --pose_relation angle_deg --delta 1 --delta_unit f
    {"KITTI_00_gt.txt", "KITTI_00_ORB.txt", "se3", kRpeRotation, 1, false, 4540, 0.11497352089152521,
     0.059583453985938666, 0.041074406677991282, 0.098329662448823213, 0.0022435537725303137, 2.1966153373107207},
    // evo_ape kitti KITTI_00_gt.txt KITTI_00_ORB.txt -as
    {"KITTI_00_gt.txt", "KITTI_00_ORB.txt", "sim3", kAte, 1, false, 4541, 0.9377090736114021, 0.87269263196930735,
     0.8446910134862976, 0.34308290082666193, 0.17951466688000844, 2.6934998636134546},
    // evo_rpe kitti KITTI_00_gt.txt KITTI_00_ORB.txt -as --pose_relation trans_part --delta 1 --delta_unit f
    {"KITTI_00_gt.txt", "KITTI_00_ORB.txt", "sim3", kRpeTranslation, 1, false, 4540, 0.02782245334356204,
     0.018952973985336217, 0.014375695516891919, 0.020368448324942553, 0.00023575389188344975, 0.30439984661188257},
    // evo_rpe kitti KITTI_00_gt.txt KITTI_00_ORB.txt -as --pose_relation angle_deg --delta 1 --delta_unit f
    {"KITTI_00_gt.txt", "KITTI_00_ORB.txt", "sim3", kRpeRotation, 1, false, 4540, 0.11497352089152521,
     0.059583453985938666, 0.041074406677991282, 0.098329662448823213, 0.0022435537725303137, 2.1966153373107207},
    // evo_ape kitti KITTI_00_gt.txt KITTI_00_ORB.txt
    {"KITTI_00_gt.txt", "KITTI_00_ORB.txt", "none", kAte, 1, false, 4541, 7.7902888826568271, 7.0117504016668404,
     6.8016316745602809, 3.3946954473076767, 4.0000000555111887e-09, 13.458508807381889},
    // evo_rpe kitti KITTI_00_gt.txt KITTI_00_ORB.txt --pose_relation trans_part --delta 1 --delta_unit f
    {"KITTI_00_gt.txt", "KITTI_00_ORB.txt", "none", kRpeTranslation, 1, false, 4540, 0.028120377017393464,
     0.019301310981393552, 0.014709043438565866, 0.020450305572286376, 0.00031240026310038854, 0.30271249059534994},
    // evo_rpe kitti KITTI_00_gt.txt KITTI_00_ORB.txt --pose_relation angle_deg --delta 1 --delta_unit f
    {"KITTI_00_gt.txt", "KITTI_00_ORB.txt", "none", kRpeRotation, 1, false, 4540, 0.11497352089152525,
     0.059583453985938666, 0.041074406677990873, 0.098329662448823268, 0.0022435537725304915, 2.1966153373107229},
    // evo_rpe kitti KITTI_00_gt.txt KITTI_00_ORB.txt -a --pose_relation trans_part --delta 10 --delta_unit f
    // --all_pairs
    {"KITTI_00_gt.txt", "KITTI_00_ORB.txt", "se3", kRpeTranslation, 10, true, 4531, 0.18934823038597923,
     0.13978226849548858, 0.11321949169180688, 0.12772497705835378, 0.0046005578872118673, 1.5153832705472317},
    // evo_rpe kitti KITTI_00_gt.txt KITTI_00_ORB.txt -a --pose_relation angle_deg --delta 10 --delta_unit f --all_pairs
    {"KITTI_00_gt.txt", "KITTI_00_ORB.txt", "se3", kRpeRotation, 10, true, 4531, 0.61146827116461244,
     0.21202394545443412, 0.093731903491213145, 0.57353229481431578, 0.0016905338522759429, 7.0664219806809312},
    // evo_rpe kitti KITTI_00_gt.txt KITTI_00_ORB.txt -a --pose_relation trans_part --delta 10 --delta_unit f
    {"KITTI_00_gt.txt", "KITTI_00_ORB.txt", "se3", kRpeTranslation, 10, false, 454, 0.19400775757969221,
     0.14151049487400033, 0.11125927424445342, 0.13271695385901586, 0.016657411822673343, 1.188534912745367},
    // evo_ape kitti KITTI_00_gt.txt KITTI_00_SPTAM.txt -a
    {"KITTI_00_gt.txt", "KITTI_00_SPTAM.txt", "se3", kAte, 1, false, 4541, 3.7384879075826114, 3.4909766330848684,
     3.6425846417432637, 1.3376748418045579, 0.6947873474062779, 7.7689774065713006},
    // evo_rpe kitti KITTI_00_gt.txt KITTI_00_SPTAM.txt -a --pose_relation trans_part --delta 1 --delta_unit f
    {"KITTI_00_gt.txt", "KITTI_00_SPTAM.txt", "se3", kRpeTranslation, 1, false, 4540, 0.034919367573240691,
     0.023406450624852179, 0.019159936772674871, 0.025913322844850487, 0.00096976133051936391, 1.136073589515664},
    // evo_rpe kitti KITTI_00_gt.txt KITTI_00_SPTAM.txt -a --pose_relation angle_deg --delta 1 --delta_unit f
    {"KITTI_00_gt.txt", "KITTI_00_SPTAM.txt", "se3", kRpeRotation, 1, false, 4540, 0.29638984112248495,
     0.24171640303990316, 0.20101844722835704, 0.171522938471981, 0.0040529206567666478, 2.503555224621318},
    // evo_ape kitti KITTI_00_gt.txt KITTI_00_SPTAM.txt -as
    {"KITTI_00_gt.txt", "KITTI_00_SPTAM.txt", "sim3", kAte, 1, false, 4541, 3.6352935643386037, 3.357305778620566,
     3.4798637552964289, 1.3942227970316032, 0.22699281394825724, 7.2918310279814902},
    // evo_rpe kitti KITTI_00_gt.txt KITTI_00_SPTAM.txt -as --pose_relation trans_part --delta 1 --delta_unit f
    {"KITTI_00_gt.txt", "KITTI_00_SPTAM.txt", "sim3", kRpeTranslation, 1, false, 4540, 0.03501725297575102,
     0.023520177022917407, 0.019239507500213748, 0.025942422376840062, 0.0010211630329939692, 1.136073589515664},
    // evo_rpe kitti KITTI_00_gt.txt KITTI_00_SPTAM.txt -as --pose_relation angle_deg --delta 1 --delta_unit f
    {"KITTI_00_gt.txt", "KITTI_00_SPTAM.txt", "sim3", kRpeRotation, 1, false, 4540, 0.29638984112248495,
     0.24171640303990316, 0.20101844722835704, 0.171522938471981, 0.0040529206567666478, 2.503555224621318},
    // evo_ape kitti KITTI_00_gt.txt KITTI_00_SPTAM.txt
    {"KITTI_00_gt.txt", "KITTI_00_SPTAM.txt", "none", kAte, 1, false, 4541, 9.2245417372378764, 8.6237035551892909,
     8.2823214096251405, 3.2747377382409044, 5.5788015308538486e-16, 14.911823227678537},
    // evo_rpe kitti KITTI_00_gt.txt KITTI_00_SPTAM.txt --pose_relation trans_part --delta 1 --delta_unit f
    {"KITTI_00_gt.txt", "KITTI_00_SPTAM.txt", "none", kRpeTranslation, 1, false, 4540, 0.034919367573240566,
     0.023406450624851992, 0.019159936772656427, 0.025913322844850494, 0.00096976133052140644, 1.136073589515664},
    // evo_rpe kitti KITTI_00_gt.txt KITTI_00_SPTAM.txt --pose_relation angle_deg --delta 1 --delta_unit f
    {"KITTI_00_gt.txt", "KITTI_00_SPTAM.txt", "none", kRpeRotation, 1, false, 4540, 0.29638984112248501,
     0.2417164030399031, 0.20101844722835638, 0.17152293847198102, 0.0040529206567667233, 2.5035552246213197},
    // evo_rpe kitti KITTI_00_gt.txt KITTI_00_SPTAM.txt -a --pose_relation trans_part --delta 10 --delta_unit f
    // --all_pairs
    {"KITTI_00_gt.txt", "KITTI_00_SPTAM.txt", "se3", kRpeTranslation, 10, true, 4531, 0.22787323053765324,
     0.18507273611959918, 0.16323150364402816, 0.13294469354160651, 0.010171560699793169, 1.705177850731491},
    // evo_rpe kitti KITTI_00_gt.txt KITTI_00_SPTAM.txt -a --pose_relation angle_deg --delta 10 --delta_unit f
    // --all_pairs
    {"KITTI_00_gt.txt", "KITTI_00_SPTAM.txt", "se3", kRpeRotation, 10, true, 4531, 1.2564509420347703,
     0.86603580635626598, 0.54764537760425835, 0.91030267046126689, 0.013398803856449523, 9.7807913875241059},
    // evo_rpe kitti KITTI_00_gt.txt KITTI_00_SPTAM.txt -a --pose_relation trans_part --delta 10 --delta_unit f
    {"KITTI_00_gt.txt", "KITTI_00_SPTAM.txt", "se3", kRpeTranslation, 10, false, 454, 0.23794204940055233,
     0.19038411080265377, 0.16657525218340052, 0.14272459222859152, 0.010374234877793964, 1.3940424406419192},
    // evo_ape tum V101_gt.txt V101_openvins.txt -a
    {"V101_gt.txt", "V101_openvins.txt", "se3", kAte, 1, false, 2760, 0.052101961085978893, 0.047082746835430803,
     0.042657759055870034, 0.022312088639022339, 0.014036962531385158, 0.12488621875724851},
    // evo_rpe tum V101_gt.txt V101_openvins.txt -a --pose_relation trans_part --delta 1 --delta_unit f
    {"V101_gt.txt", "V101_openvins.txt", "se3", kRpeTranslation, 1, false, 2759, 0.0011375254423658828,
     0.00076397412597284961, 0.00067374689279787775, 0.00084279752424512859, 4.4216687990457544e-05,
     0.038450513788171041},
    // evo_rpe tum V101_gt.txt V101_openvins.txt -a --pose_relation angle_deg --delta 1 --delta_unit f
    {"V101_gt.txt", "V101_openvins.txt", "se3", kRpeRotation, 1, false, 2759, 0.017912050771277478,
     0.010378113762072297, 0.0089383060450947301, 0.014599188935495959, 0.0006065208414184148, 0.69502148607656378},
    // evo_ape tum V101_gt.txt V101_openvins.txt -as
    {"V101_gt.txt", "V101_openvins.txt", "sim3", kAte, 1, false, 2760, 0.05155279012247773, 0.045267554069737627,
     0.041005532350012995, 0.024668577542201683, 0.012243418335323022, 0.13120495647504624},
    // evo_rpe tum V101_gt.txt V101_openvins.txt -as --pose_relation trans_part --delta 1 --delta_unit f
    {"V101_gt.txt", "V101_openvins.txt", "sim3", kRpeTranslation, 1, false, 2759, 0.001125612248787259,
     0.00074485422173924132, 0.00064844332477112911, 0.00084391653792133964, 3.1060346928721269e-05,
     0.038604615838004376},
    // evo_rpe tum V101_gt.txt V101_openvins.txt -as --pose_relation angle_deg --delta 1 --delta_unit f
    {"V101_gt.txt", "V101_openvins.txt", "sim3", kRpeRotation, 1, false, 2759, 0.017912050771277478,
     0.010378113762072297, 0.0089383060450947301, 0.014599188935495959, 0.0006065208414184148, 0.69502148607656378},
    // evo_ape tum V101_gt.txt V101_openvins.txt
    {"V101_gt.txt", "V101_openvins.txt", "none", kAte, 1, false, 2760, 2.702388478468742, 2.6964078497391699,
     2.7091111297196262, 0.17968916613304162, 2.2318458567766282, 3.133100758049284},
    // evo_rpe tum V101_gt.txt V101_openvins.txt --pose_relation trans_part --delta 1 --delta_unit f
    {"V101_gt.txt", "V101_openvins.txt", "none", kRpeTranslation, 1, false, 2759, 0.0011375254423658791,
     0.00076397412597284582, 0.00067374689279809438, 0.00084279752424512675, 4.421668799066363e-05,
     0.038450513788171138},
    // evo_rpe tum V101_gt.txt V101_openvins.txt --pose_relation angle_deg --delta 1 --delta_unit f
    {"V101_gt.txt", "V101_openvins.txt", "none", kRpeRotation, 1, false, 2759, 0.017912050771277482,
     0.010378113762072271, 0.0089383060450953233, 0.014599188935495982, 0.0006065208414187792, 0.695021486076565},
    // evo_rpe tum V101_gt.txt V101_openvins.txt -a --pose_relation trans_part --delta 10 --delta_unit f --all_pairs
    {"V101_gt.txt", "V101_openvins.txt", "se3", kRpeTranslation, 10, true, 2750, 0.0066072909564167115,
     0.0058381871357283798, 0.0053269538257029025, 0.0030938430391604737, 0.00020399497186528076, 0.048971374752403159},
    // evo_rpe tum V101_gt.txt V101_openvins.txt -a --pose_relation angle_deg --delta 10 --delta_unit f --all_pairs
    {"V101_gt.txt", "V101_openvins.txt", "se3", kRpeRotation, 10, true, 2750, 0.10212110192806587, 0.087964044534599176,
     0.080101186914954714, 0.051875295932818269, 0.0032085653335826559, 0.62639220044248634},
    // evo_rpe tum V101_gt.txt V101_openvins.txt -a --pose_relation trans_part --delta 10 --delta_unit f
    {"V101_gt.txt", "V101_openvins.txt", "se3", kRpeTranslation, 10, false, 275, 0.007069486215031567,
     0.005933902193620999, 0.0052852074450419166, 0.0038427125967291976, 0.00052939914036125978, 0.048971374752403159},
    // evo_ape tum freiburg1_xyz-groundtruth.txt freiburg1_xyz-rgbdslam.txt -a
    {"freiburg1_xyz-groundtruth.txt", "freiburg1_xyz-rgbdslam.txt", "se3", kAte, 1, false, 785, 0.013470088849733684,
     0.012024498709110232, 0.011183186775061124, 0.0060708092058906031, 0.00095504618131778552, 0.034759545895009188},
    // evo_rpe tum freiburg1_xyz-groundtruth.txt freiburg1_xyz-rgbdslam.txt -a --pose_relation trans_part --delta 1
    // --delta_unit f
    {"freiburg1_xyz-groundtruth.txt", "freiburg1_xyz-rgbdslam.txt", "se3", kRpeTranslation, 1, false, 784,
     0.0057643708489283083, 0.0048156094702039602, 0.0041388577993643969, 0.0031682608343468819, 0.00017106115346194139,
     0.020865814532329583},
    // evo_rpe tum freiburg1_xyz-groundtruth.txt freiburg1_xyz-rgbdslam.txt -a --pose_relation angle_deg --delta 1
    // --delta_unit f
    {"freiburg1_xyz-groundtruth.txt", "freiburg1_xyz-rgbdslam.txt", "se3", kRpeRotation, 1, false, 784,
     0.35361316104479829, 0.30030658114004039, 0.26213899966944754, 0.18670357518825065, 0.016937143523711184,
     1.6332960623334374},
    // evo_ape tum freiburg1_xyz-groundtruth.txt freiburg1_xyz-rgbdslam.txt -as
    {"freiburg1_xyz-groundtruth.txt", "freiburg1_xyz-rgbdslam.txt", "sim3", kAte, 1, false, 785, 0.013389384904168198,
     0.011986889624888907, 0.011133899090810763, 0.0059657443150622847, 0.00073270670522917157, 0.034846144852261243},
    // evo_rpe tum freiburg1_xyz-groundtruth.txt freiburg1_xyz-rgbdslam.txt -as --pose_relation trans_part --delta 1
    // --delta_unit f
    {"freiburg1_xyz-groundtruth.txt", "freiburg1_xyz-rgbdslam.txt", "sim3", kRpeTranslation, 1, false, 784,
     0.0058056945631216623, 0.0048472459269017255, 0.0041546253372883807, 0.0031953554237979637, 0.00017450017342692296,
     0.021027081882492551},
    // evo_rpe tum freiburg1_xyz-groundtruth.txt freiburg1_xyz-rgbdslam.txt -as --pose_relation angle_deg --delta 1
    // --delta_unit f
    {"freiburg1_xyz-groundtruth.txt", "freiburg1_xyz-rgbdslam.txt", "sim3", kRpeRotation, 1, false, 784,
     0.35361316104479829, 0.30030658114004039, 0.26213899966944754, 0.18670357518825065, 0.016937143523711184,
     1.6332960623334374},
    // evo_ape tum freiburg1_xyz-groundtruth.txt freiburg1_xyz-rgbdslam.txt
    {"freiburg1_xyz-groundtruth.txt", "freiburg1_xyz-rgbdslam.txt", "none", kAte, 1, false, 785, 0.020079418378506592,
     0.018062518430696541, 0.016517756173282164, 0.0087708876608845084, 0.0012561023047507462, 0.043289433884032329},
    // evo_rpe tum freiburg1_xyz-groundtruth.txt freiburg1_xyz-rgbdslam.txt --pose_relation trans_part --delta 1
    // --delta_unit f
    {"freiburg1_xyz-groundtruth.txt", "freiburg1_xyz-rgbdslam.txt", "none", kRpeTranslation, 1, false, 784,
     0.0057643708489283074, 0.0048156094702039567, 0.004138857799364154, 0.0031682608343468867, 0.00017106115346219699,
     0.02086581453232984},
    // evo_rpe tum freiburg1_xyz-groundtruth.txt freiburg1_xyz-rgbdslam.txt --pose_relation angle_deg --delta 1
    // --delta_unit f
    {"freiburg1_xyz-groundtruth.txt", "freiburg1_xyz-rgbdslam.txt", "none", kRpeRotation, 1, false, 784,
     0.3536131610447984, 0.3003065811400405, 0.26213899966944898, 0.18670357518825084, 0.016937143523711472,
     1.6332960623334383},
    // evo_rpe tum freiburg1_xyz-groundtruth.txt freiburg1_xyz-rgbdslam.txt -a --pose_relation trans_part --delta 10
    // --delta_unit f --all_pairs
    {"freiburg1_xyz-groundtruth.txt", "freiburg1_xyz-rgbdslam.txt", "se3", kRpeTranslation, 10, true, 775,
     0.014040675998645396, 0.012023417812303887, 0.010939370434006822, 0.0072510693424977339, 0.00036774613220040938,
     0.048023289418413266},
    // evo_rpe tum freiburg1_xyz-groundtruth.txt freiburg1_xyz-rgbdslam.txt -a --pose_relation angle_deg --delta 10
    // --delta_unit f --all_pairs
    {"freiburg1_xyz-groundtruth.txt", "freiburg1_xyz-rgbdslam.txt", "se3", kRpeRotation, 10, true, 775,
     0.67477774773311106, 0.5897482506944679, 0.53607097713558371, 0.32790548888145366, 0.049079338508365468,
     1.7221765649076803},
    // evo_rpe tum freiburg1_xyz-groundtruth.txt freiburg1_xyz-rgbdslam.txt -a --pose_relation trans_part --delta 10
    // --delta_unit f
    {"freiburg1_xyz-groundtruth.txt", "freiburg1_xyz-rgbdslam.txt", "se3", kRpeTranslation, 10, false, 78,
     0.01461013202388887, 0.01247707696847594, 0.011981234060699758, 0.0076012175391966183, 0.0010349715017427381,
     0.043153861730255406},
    // evo_ape tum fr2_desk_groundtruth.txt fr2_desk_ORB.txt -a
    {"fr2_desk_groundtruth.txt", "fr2_desk_ORB.txt", "se3", kAte, 1, false, 2174, 0.0081189775620449118,
     0.0074917768702161382, 0.0074146298293169075, 0.0031290695070393085, 0.00034963619840676515, 0.024299593694384707},
    // evo_rpe tum fr2_desk_groundtruth.txt fr2_desk_ORB.txt -a --pose_relation trans_part --delta 1 --delta_unit f
    {"fr2_desk_groundtruth.txt", "fr2_desk_ORB.txt", "se3", kRpeTranslation, 1, false, 2173, 0.0034903213747872882,
     0.0030380874175009644, 0.0027502883862043372, 0.0017182456584898874, 0.0001319690055882982, 0.019484678920168065},
    // evo_rpe tum fr2_desk_groundtruth.txt fr2_desk_ORB.txt -a --pose_relation angle_deg --delta 1 --delta_unit f
    {"fr2_desk_groundtruth.txt", "fr2_desk_ORB.txt", "se3", kRpeRotation, 1, false, 2173, 0.28051922626732645,
     0.22955611958091893, 0.18781845711906081, 0.16122972513953604, 0.0060389459196573203, 1.2594035027080073},
    // evo_ape tum fr2_desk_groundtruth.txt fr2_desk_ORB.txt -as
    {"fr2_desk_groundtruth.txt", "fr2_desk_ORB.txt", "sim3", kAte, 1, false, 2174, 0.0061231630301572266,
     0.005586197318706093, 0.0053052250758525432, 0.0025074937707529996, 0.00018979580960878624, 0.021476785562787291},
    // evo_rpe tum fr2_desk_groundtruth.txt fr2_desk_ORB.txt -as --pose_relation trans_part --delta 1 --delta_unit f
    {"fr2_desk_groundtruth.txt", "fr2_desk_ORB.txt", "sim3", kRpeTranslation, 1, false, 2173, 0.003485016890888194,
     0.0030303829997873092, 0.0027455208712606595, 0.0017210815217113004, 0.00013944393314212748, 0.020907743940873382},
    // evo_rpe tum fr2_desk_groundtruth.txt fr2_desk_ORB.txt -as --pose_relation angle_deg --delta 1 --delta_unit f
    {"fr2_desk_groundtruth.txt", "fr2_desk_ORB.txt", "sim3", kRpeRotation, 1, false, 2173, 0.28051922626732645,
     0.22955611958091893, 0.18781845711906081, 0.16122972513953604, 0.0060389459196573203, 1.2594035027080073},
    // evo_ape tum fr2_desk_groundtruth.txt fr2_desk_ORB.txt
    {"fr2_desk_groundtruth.txt", "fr2_desk_ORB.txt", "none", kAte, 1, false, 2174, 3.17399354190223, 2.9496938875994747,
     2.5946424649750952, 1.1719816438389132, 1.4603442833644174, 5.066735062280106},
    // evo_rpe tum fr2_desk_groundtruth.txt fr2_desk_ORB.txt --pose_relation trans_part --delta 1 --delta_unit f
    {"fr2_desk_groundtruth.txt", "fr2_desk_ORB.txt", "none", kRpeTranslation, 1, false, 2173, 0.0034903213747872895,
     0.0030380874175009649, 0.0027502883862039998, 0.0017182456584898887, 0.00013196900558788363, 0.019484678920167454},
    // evo_rpe tum fr2_desk_groundtruth.txt fr2_desk_ORB.txt --pose_relation angle_deg --delta 1 --delta_unit f
    {"fr2_desk_groundtruth.txt", "fr2_desk_ORB.txt", "none", kRpeRotation, 1, false, 2173, 0.28051922626732667,
     0.22955611958091907, 0.18781845711906089, 0.16122972513953615, 0.0060389459196585468, 1.2594035027080082},
    // evo_rpe tum fr2_desk_groundtruth.txt fr2_desk_ORB.txt -a --pose_relation trans_part --delta 10 --delta_unit f
    // --all_pairs
    {"fr2_desk_groundtruth.txt", "fr2_desk_ORB.txt", "se3", kRpeTranslation, 10, true, 2164, 0.005841796673881329,
     0.005176504927493707, 0.0047017079068960785, 0.002707468395864361, 0.00049105349374509979, 0.021287541537058495},
    // evo_rpe tum fr2_desk_groundtruth.txt fr2_desk_ORB.txt -a --pose_relation angle_deg --delta 10 --delta_unit f
    // --all_pairs
    {"fr2_desk_groundtruth.txt", "fr2_desk_ORB.txt", "se3", kRpeRotation, 10, true, 2164, 0.39590177022740614,
     0.33793799337644254, 0.29324354781452111, 0.20624287697250873, 0.014532259506300485, 1.6511982489958905},
    // evo_rpe tum fr2_desk_groundtruth.txt fr2_desk_ORB.txt -a --pose_relation trans_part --delta 10 --delta_unit f
    {"fr2_desk_groundtruth.txt", "fr2_desk_ORB.txt", "se3", kRpeTranslation, 10, false, 217, 0.006234649485655018,
     0.0054300059237620286, 0.0048796009739473945, 0.0030636399718125605, 0.00075164281141180099, 0.021287541537058495},
};

const TrajectoryInput& input(const std::string& name) {
  static std::map<std::string, TrajectoryInput> cache;
  auto it = cache.find(name);
  if (it == cache.end()) it = cache.emplace(name, readTrajectoryInput(kTrajectories + name, "")).first;
  return it->second;
}

const Evaluation& evaluationOf(const EvoReference& ref) {
  static std::map<std::string, Evaluation> cache;
  const std::string key = std::string(ref.gt) + "|" + ref.est + "|" + ref.align + "|" + std::to_string(ref.delta) +
                          (ref.all_pairs ? "|all" : "");
  auto it = cache.find(key);
  if (it == cache.end()) {
    EvaluationOptions options;
    options.alignment = parseAlignment(ref.align);
    options.rpe.delta = ref.delta;
    options.rpe.all_pairs = ref.all_pairs;
    it = cache.emplace(key, evaluateTrajectory(input(ref.est), input(ref.gt), options)).first;
  }
  return it->second;
}

// 1e-6 relative, as the issue asks (the agreement measured is about 1e-10).
void expectAgrees(double ours, double evo, const std::string& what) {
  EXPECT_LE(std::abs(ours - evo), 1e-6 * std::abs(evo)) << what << ": ours " << ours << ", evo " << evo;
}

}  // namespace

TEST(EvoAgreement, AteAndRpeOnSharedPairs) {
  for (const EvoReference& ref : kEvo) {
    const Evaluation& ev = evaluationOf(ref);
    const ErrorStatistics& s = ref.metric == kAte              ? ev.ate
                               : ref.metric == kRpeTranslation ? ev.rpe_translation_m
                                                               : ev.rpe_rotation_deg;
    const std::string what = std::string(ref.est) + " vs " + ref.gt + ", " + ref.align + ", " +
                             (ref.metric == kAte              ? "ATE"
                              : ref.metric == kRpeTranslation ? "RPE m"
                                                              : "RPE deg") +
                             ", delta " + std::to_string(ref.delta) + (ref.all_pairs ? " all pairs" : "");
    ASSERT_EQ(s.count, ref.count) << what;
    expectAgrees(s.rmse, ref.rmse, what + " rmse");
    expectAgrees(s.mean, ref.mean, what + " mean");
    expectAgrees(s.median, ref.median, what + " median");
    expectAgrees(s.std, ref.std, what + " std");
    expectAgrees(s.min, ref.min, what + " min");
    expectAgrees(s.max, ref.max, what + " max");
  }
}

TEST(EvoAgreement, PairsByIndexForKittiAndByTimeForTum) {
  const EvoReference kitti{"KITTI_00_gt.txt", "KITTI_00_ORB.txt", "se3", kAte, 1, false, 0, 0, 0, 0, 0, 0, 0};
  EXPECT_TRUE(evaluationOf(kitti).pairs.by_index);
  EXPECT_DOUBLE_EQ(evaluationOf(kitti).coverage.fraction, 1.0);
  const EvoReference tum{"V101_gt.txt", "V101_openvins.txt", "se3", kAte, 1, false, 0, 0, 0, 0, 0, 0, 0};
  const Evaluation& ev = evaluationOf(tum);
  EXPECT_FALSE(ev.pairs.by_index);
  for (size_t k = 0; k < ev.pairs.size(); ++k) EXPECT_LE(std::abs(ev.est_stamps[k] - ev.gt_stamps[k]), 0.01);
  // OpenVINS starts 5.6 s after the ground truth and has short gaps: most, not all, of the span.
  EXPECT_GT(ev.coverage.fraction, 0.9);
  EXPECT_LT(ev.coverage.fraction, 1.0);
}
