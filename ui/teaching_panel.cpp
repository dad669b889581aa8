#include "ui/teaching_panel.hpp"

namespace fl::ui {

TeachingPanel::TeachingPanel(QWidget* parent) : QTextBrowser(parent) {
  setOpenExternalLinks(false);
  setHtml(html());
}

QString TeachingPanel::html() {
  return QStringLiteral(R"(
<h3>What you are seeing</h3>
<p>A <b>periodic cell</b> of glass beads: a particle leaving one face re-enters through the opposite one,
so the small box behaves like a piece of an infinite soil element. Compression is positive; z is vertical
(the axial direction).</p>

<h4>Stresses</h4>
<p><b>p&prime;</b> = (&sigma;&prime;<sub>xx</sub> + &sigma;&prime;<sub>yy</sub> + &sigma;&prime;<sub>zz</sub>)/3,
the mean <i>effective</i> stress carried by the grain contacts. <b>q</b> = &sigma;&prime;<sub>zz</sub> &minus;
(&sigma;&prime;<sub>xx</sub> + &sigma;&prime;<sub>yy</sub>)/2, the deviator stress. The <b>stress path</b>
plots q against p&prime;: isotropic compression runs along q = 0, shearing moves up or down.</p>

<h4>&tau;&ndash;&gamma; loops</h4>
<p>&tau; = q/2 and &gamma; = &epsilon;<sub>a</sub> &minus; &epsilon;<sub>r</sub>. In a strain-controlled cycle the
specimen is pushed between &plusmn; the amplitude; the loop's secant slope is the shear stiffness
<b>G<sub>sec</sub></b> and its area the energy lost in friction (damping).</p>

<h4>Drained and undrained</h4>
<p><b>Drained</b>: water can leave, the lateral stress is held and the volume changes (&epsilon;<sub>v</sub>).
<b>Undrained</b>: the pores are sealed, so the volume is held constant; the tendency to contract then shows
as a rise of pore pressure <b>&Delta;u</b>, i.e. a drop of p&prime;. When p&prime; nears zero the sand liquefies.</p>

<h4>Coordination</h4>
<p><b>Z</b> = 2C/N, contacts per particle. <b>Z<sub>m</sub></b>, the mechanical coordination number,
leaves out the <i>rattlers</i> (particles with 0 or 1 contact) that carry no load; about 4 is the
minimum for a stable frictional packing.</p>

<h4>Fabric and anisotropy a</h4>
<p>The <b>fabric tensor</b> &phi; = &lang;n&otimes;n&rang; averages the contact normals. Its anisotropy
<b>a</b> says how much more contacts point one way: <b>a<sub>2D</sub></b> (Rothenburg&ndash;Bathurst) fits
E(&theta;) = [1 + a cos 2(&theta; &minus; &theta;<sub>a</sub>)]/2&pi; to the normals projected on a vertical plane
(the paper's measure: 0.018 isotropic, 0.213 anisotropic specimen); <b>a<sub>3D</sub></b> is the 3D
analogue from &phi;<sub>zz</sub> &minus; (&phi;<sub>xx</sub> + &phi;<sub>yy</sub>)/2. The two are different
numbers for the same packing; both are labelled.</p>

<h4>Rose diagrams</h4>
<p>A polar histogram of contact directions in a plane: the radius in each direction is how many normals point
that way (the white circle = isotropic). A rose stretched vertically means the packing mostly carries load
vertically. The 3D panel is the same on a sphere; its lines are the fabric's principal directions. Tick
&laquo;weight by normal force&raquo; to see where the <i>force</i> goes rather than where the contacts are.</p>

<h4>Force chains</h4>
<p>Lines from a particle's centre to its neighbour's, drawn for contacts carrying more than the threshold
(by default the mean normal force); thicker and redder = stronger. A minority of strong chains carries most
of the deviator load; the weak network around them keeps them from buckling.</p>

<h4>K<sub>0</sub> and OCR</h4>
<p><b>K<sub>0</sub></b> = &sigma;&prime;<sub>h</sub>/&sigma;&prime;<sub>v</sub> under one-dimensional
(no lateral strain) loading, as in the ground. <b>OCR</b> = &sigma;&prime;<sub>v,max</sub>/&sigma;&prime;<sub>v</sub>,
the overconsolidation ratio: unloading from a past maximum raises K<sub>0</sub> and stiffens the soil.</p>
)");
}

}  // namespace fl::ui
