"""The published relations the three packages use: one :class:`Reference` per work.

Every citation in the source of ``craters``, ``latlong`` and ``dem`` (``Pike 1977``,
``Fassett & Thomson (2014)``, ``Martin, Parkes & Dunstan 2014``, ``Li et al. 2022`` ...)
names an entry here by its first author's surname and year, and every entry is cited
where it is used (``tests/test_references.py`` checks both ways). A ``doi`` is given only
where a record was found that shows it for the same title; books, proceedings, abstracts
and works whose DOI was not confirmed have ``doi=None`` and an identifier (publisher, ISBN,
ADS bibcode, PMID) in ``venue``. A title that no record confirmed is kept but marked
``(title not confirmed)`` in ``venue``; where no title is known at all the title is
``(title not confirmed; cited by venue)``.

The table :data:`REFERENCES` is grouped by topic: the source papers (Martin et al.'s
two, Li et al.'s two), crater shapes and their scaling, degradation, production and
chronology, body radii, the asteroid presets (Eros, Itokawa, Bennu), gravity, terrain,
implicit surfaces and meshes, numerics, randomness, and the sensors (ray tracing, cameras,
stars, photometry, light between surfaces and from planets).

Examples
--------
>>> reference("pike1977").cite()
'Pike 1977'
>>> reference("fassett2014").doi
'10.1002/2014JE004698'
"""

from __future__ import annotations

import dataclasses
import difflib
import re
import types

__all__ = ["REFERENCES", "Reference", "reference"]

_KEY = re.compile(r"[a-z]+[0-9]{4}[a-z]*")
_DOI = re.compile(r"10\.[0-9]{4,9}/\S+")
_UNCONFIRMED = "(title not confirmed; cited by venue)"


@dataclasses.dataclass(frozen=True, slots=True)
class Reference:
    """One published work the code uses."""

    key: str
    """Short name: first author's surname, year, and a word where a year holds two."""
    authors: tuple[str, ...]
    """``"Surname, I."`` each, in order; a last ``"et al."`` stands for the rest."""
    year: int
    """Year of publication."""
    title: str
    """Title of the work."""
    venue: str
    """Journal, volume and pages, or book, proceedings, publisher, ISBN, ADS bibcode."""
    doi: str | None = None
    """DOI (``10.NNNN/...``) where one was confirmed, else None."""

    def __post_init__(self):
        if not _KEY.fullmatch(self.key):
            raise ValueError(f"`key` must be surname + year (+ word); got {self.key!r}")
        if not self.authors or not all(isinstance(a, str) and a for a in self.authors):
            raise ValueError(f"`authors` must be non-empty strings; got {self.authors!r}")
        if not 1600 <= self.year <= 2100:
            raise ValueError(f"`year` must be in [1600, 2100]; got {self.year!r}")
        if self.doi is not None and not _DOI.fullmatch(self.doi):
            raise ValueError(f"`doi` must look like 10.NNNN/...; got {self.doi!r}")

    @property
    def surnames(self) -> tuple[str, ...]:
        """The authors' surnames (without the ``"et al."``)."""
        return tuple(a.split(",")[0] for a in self.authors if a != "et al.")

    def cite(self) -> str:
        """The short citation: ``Pike 1977``, ``Fassett & Thomson 2014``, ``Li et al. 2022``."""
        names = self.surnames
        if len(names) > 2 or "et al." in self.authors:
            return f"{names[0]} et al. {self.year}"
        return f"{' & '.join(names)} {self.year}"

    def __str__(self) -> str:
        doi = f", doi:{self.doi}" if self.doi else ""
        return f"{'; '.join(self.authors)} ({self.year}) {self.title}. {self.venue}{doi}"


def _entries(*refs: Reference) -> types.MappingProxyType:
    return types.MappingProxyType({r.key: r for r in refs})


_R = Reference
#: Every reference by key (module notes).
REFERENCES = _entries(
    # ---------------------------------------------------------------- source papers
    _R("martin2014asteroid", ("Martin, I.", "Parkes, S.", "Dunstan, M.", "Rowell, N."), 2014,
       "Asteroid modeling for testing spacecraft approach and landing",
       "IEEE Computer Graphics and Applications 34, 52 (DOI not confirmed)"),
    _R("martin2014lunar", ("Martin, I.", "Parkes, S.", "Dunstan, M."), 2014,
       "Modeling cratered surfaces with real and synthetic terrain for testing planetary "
       "landers", "IEEE Transactions on Aerospace and Electronic Systems 50(4), 2916-2928",
       "10.1109/TAES.2014.120282"),
    _R("li2020", ("Li, X.-Z.", "Weller, R.", "Zachmann, G."), 2020,
       "Procedural 3D asteroid surface detail synthesis",
       "Eurographics 2020 - Short Papers (Wilkie & Banterle, eds.), The Eurographics "
       "Association (DOI not confirmed)"),
    _R("li2022", ("Li, X.", "Vincent, J.-B.", "Weller, R.", "Zachmann, G."), 2022,
       "Numerical approach to synthesizing realistic asteroid surfaces from morphological "
       "parameters", "Astronomy & Astrophysics 659, A176", "10.1051/0004-6361/202140709"),
    # ---------------------------------------------------------------- crater shapes
    _R("pike1977", ("Pike, R. J.",), 1977,
       "Size-dependence in the shape of fresh impact craters on the Moon",
       "Impact and Explosion Cratering: Planetary and Terrestrial Implications (Roddy, Pepin & "
       "Merrill, eds.), Pergamon, 489-509"),
    _R("pike1980", ("Pike, R. J.",), 1980,
       "Control of crater morphology by gravity and target type: Mars, Earth, Moon",
       "Proceedings of the 11th Lunar and Planetary Science Conference, 2159-2189"),
    _R("pike1985", ("Pike, R. J.",), 1985,
       "Some morphologic systematics of complex impact structures",
       "Meteoritics 20(1), 49-68 (title not confirmed)"),
    _R("pike1988", ("Pike, R. J.",), 1988, "Geomorphology of impact craters on Mercury",
       "Mercury (Vilas, Chapman & Matthews, eds.), University of Arizona Press, 165-273"),
    _R("hale1979", ("Hale, W.", "Head, J. W."), 1979,
       "Central peaks in lunar craters: Morphology and morphometry",
       "Proceedings of the 10th Lunar and Planetary Science Conference"),
    _R("melosh1989", ("Melosh, H. J.",), 1989, "Impact Cratering: A Geologic Process",
       "Oxford University Press, New York"),
    _R("baker2011", ("Baker, D. M. H.", "Head, J. W.", "Fassett, C. I.", "Kadish, S. J.",
                     "Smith, D. E.", "Zuber, M. T.", "Neumann, G. A."), 2011,
       "The transition from complex crater to peak-ring basin on the Moon: New observations "
       "from the Lunar Orbiter Laser Altimeter (LOLA) instrument", "Icarus 214(2), 377-393",
       "10.1016/j.icarus.2011.05.030"),
    _R("garvin1998", ("Garvin, J. B.", "Frawley, J. J."), 1998,
       "Geometric properties of Martian impact craters: Preliminary results from the Mars "
       "Orbiter Laser Altimeter", "Geophysical Research Letters 25(24), 4405-4408",
       "10.1029/1998GL900177"),
    _R("garvin2003", ("Garvin, J. B.", "Sakimoto, S. E. H.", "Frawley, J. J."), 2003,
       "Craters on Mars: Global geometric properties from gridded MOLA topography",
       "Sixth International Conference on Mars, abstract 3277, Lunar and Planetary Institute "
       "(title not confirmed)"),
    _R("stopar2017", ("Stopar, J. D.", "Robinson, M. S.", "Barnouin, O. S.", "McEwen, A. S.",
                      "Speyerer, E. J.", "Henriksen, M. R.", "Sutton, S. S."), 2017,
       "Relative depths of simple craters and the nature of the lunar regolith",
       "Icarus 298, 34-48 (DOI not confirmed)"),
    _R("barnouin2012", ("Barnouin, O. S.", "Zuber, M. T.", "Smith, D. E.", "et al."), 2012,
       "The morphology of craters on Mercury: Results from MESSENGER flybys",
       "Icarus 219(1), 414-427 (title not confirmed)"),
    _R("grieve1987", ("Grieve, R. A. F.",), 1987, "Terrestrial impact structures",
       "Annual Review of Earth and Planetary Sciences 15, 245-270 (title not confirmed; DOI not "
       "confirmed)"),
    _R("sun2023", ("Sun, Q.", "Fa, W.", "Zhu, M.-H.", "Du, J."), 2023,
       "Morphological characteristics of impact craters with diameters of 5-20 km on the "
       "Moon", "Icarus 115688", "10.1016/j.icarus.2023.115688"),
    _R("hiesinger2016", ("Hiesinger, H.", "Marchi, S.", "Schmedemann, N.", "et al."), 2016,
       "Cratering on Ceres: Implications for its crust and evolution",
       "Science 353(6303), aaf4759", "10.1126/science.aaf4759"),
    _R("gou2018", ("Gou, S.", "Yue, Z.", "Di, K.", "Liu, Z."), 2018,
       "A global catalogue of Ceres impact craters >= 1 km and preliminary analysis",
       "Icarus 302, 296-307", "10.1016/j.icarus.2017.11.028"),
    _R("marchi2015", ("Marchi, S.", "Chapman, C. R.", "Barnouin, O. S.", "Richardson, J. E.",
                      "Vincent, J.-B."), 2015, "Cratering on asteroids",
       "Asteroids IV (Michel, DeMeo & Bottke, eds.), University of Arizona Press, Tucson, 725 "
       "(title not confirmed)"),
    _R("daly2020", ("Daly, R. T.", "Bierhaus, E. B.", "Barnouin, O. S.", "et al."), 2020,
       "The morphometry of impact craters on Bennu",
       "Geophysical Research Letters 47(24), e2020GL089672", "10.1029/2020GL089672"),
    _R("mcgetchin1973", ("McGetchin, T. R.", "Settle, M.", "Head, J. W."), 1973,
       "Radial thickness variation in impact crater ejecta: Implications for lunar basin "
       "deposits", "Earth and Planetary Science Letters 20(2), 226-236",
       "10.1016/0012-821X(73)90162-3"),
    # ---------------------------------------------------------------- degradation
    _R("fassett2014", ("Fassett, C. I.", "Thomson, B. J."), 2014,
       "Crater degradation on the lunar maria: Topographic diffusion and the rate of erosion "
       "on the Moon", "Journal of Geophysical Research: Planets 119(10), 2255-2271",
       "10.1002/2014JE004698"),
    _R("fassett2015", ("Fassett, C. I.", "Thomson, B. J."), 2015, _UNCONFIRMED,
       "46th Lunar and Planetary Science Conference, abstract 1120 (ADS "
       "2015LPI....46.1120F)"),
    _R("guizar2004", ("Guizar-Sicairos, M.", "Gutiérrez-Vega, J. C."), 2004,
       "Computation of quasi-discrete Hankel transforms of integer order for propagating "
       "optical wave fields", "Journal of the Optical Society of America A 21(1), 53-58",
       "10.1364/JOSAA.21.000053"),
    # ---------------------------------------------------------------- chronology
    _R("neukum1983", ("Neukum, G.",), 1983,
       "Meteoritenbombardement und Datierung planetarer Oberflächen",
       "Habilitation thesis, Ludwig-Maximilians-Universität München"),
    _R("neukum2001", ("Neukum, G.", "Ivanov, B. A.", "Hartmann, W. K."), 2001,
       "Cratering records in the inner solar system in relation to the lunar reference "
       "system", "Space Science Reviews 96, 55-86", "10.1023/A:1011989004263"),
    _R("neukum2001mercury", ("Neukum, G.", "Oberst, J.", "Hoffmann, H.", "Wagner, R.",
                             "Ivanov, B. A."), 2001,
       "Geologic evolution and cratering history of Mercury",
       "Planetary and Space Science 49(14-15), 1507-1521 (DOI not confirmed)"),
    _R("ivanov2001", ("Ivanov, B. A.",), 2001, "Mars/Moon cratering rate ratio estimates",
       "Space Science Reviews 96, 87-104", "10.1023/A:1011941121102"),
    _R("hartmann2001", ("Hartmann, W. K.", "Neukum, G."), 2001,
       "Cratering chronology and the evolution of Mars", "Space Science Reviews 96, 165-194",
       "10.1023/A:1011945222010"),
    _R("strom1988", ("Strom, R. G.", "Neukum, G."), 1988,
       "The cratering record on Mercury and the origin of impacting objects",
       "Mercury (Vilas, Chapman & Matthews, eds.), University of Arizona Press, 336-373"),
    _R("schmedemann2014vesta", ("Schmedemann, N.", "Kneissl, T.", "Ivanov, B. A.", "et al."),
       2014, "The cratering record, chronology and surface ages of (4) Vesta in comparison "
       "to smaller asteroids and the ages of HED meteorites",
       "Planetary and Space Science 103, 104-130", "10.1016/j.pss.2014.04.004"),
    _R("schmedemann2014phobos", ("Schmedemann, N.", "Michael, G. G.", "Ivanov, B. A.",
                                 "Murray, J. B.", "Neukum, G."), 2014,
       "The age of Phobos and its largest crater, Stickney",
       "Planetary and Space Science 102, 152-163", "10.1016/j.pss.2014.04.009"),
    _R("trask1966", ("Trask, N. J.",), 1966,
       "Size and spatial distribution of craters estimated from Ranger photographs",
       "Jet Propulsion Laboratory Technical Report 32-800, 252-263"),
    _R("hartmann1984", ("Hartmann, W. K.",), 1984,
       "Does crater 'saturation equilibrium' occur in the solar system?",
       "Icarus 60(1), 56-74", "10.1016/0019-1035(84)90138-6"),
    _R("michael2010", ("Michael, G. G.", "Neukum, G."), 2010,
       "Planetary surface dating from crater size-frequency distribution measurements: "
       "Partial resurfacing events and statistical age uncertainty",
       "Earth and Planetary Science Letters 294, 223-229", "10.1016/j.epsl.2009.12.041"),
    _R("michael2013", ("Michael, G. G.",), 2013,
       "Planetary surface dating from crater size-frequency distribution measurements: "
       "Multiple resurfacing episodes and differential isochron fitting", "Icarus 226(1)",
       "10.1016/j.icarus.2013.07.004"),
    _R("kneissl2011", ("Kneissl, T.", "van Gasselt, S.", "Neukum, G."), 2011,
       "Map-projection-independent crater size-frequency determination in GIS environments: "
       "New software tool for ArcGIS", "Planetary and Space Science 59(11-12), 1243-1254",
       "10.1016/j.pss.2010.03.015"),
    _R("robbins2019", ("Robbins, S. J.",), 2019,
       "A new global database of lunar impact craters >1-2 km: 1. Crater locations and "
       "sizes, comparisons with published databases, and global analysis",
       "Journal of Geophysical Research: Planets 124(4), 871-892", "10.1029/2018JE005592"),
    # ---------------------------------------------------------------- body radii
    _R("archinal2018", ("Archinal, B. A.", "et al."), 2018,
       "Report of the IAU Working Group on Cartographic Coordinates and Rotational Elements: "
       "2015", "Celestial Mechanics and Dynamical Astronomy 130(3), 22",
       "10.1007/s10569-017-9805-5"),
    _R("russell2012", ("Russell, C. T.", "et al."), 2012,
       "Dawn at Vesta: Testing the protoplanetary paradigm", "Science 336, 684-686",
       "10.1126/science.1219381"),
    _R("park2016", ("Park, R. S.", "et al."), 2016,
       "A partially differentiated interior for (1) Ceres deduced from its gravity field and "
       "shape", "Nature 537, 515-517", "10.1038/nature18955"),
    _R("thomas1994", ("Thomas, P. C.", "et al."), 1994,
       "The shape of Gaspra", "Icarus 107 (title not confirmed; DOI not confirmed)"),
    _R("thomas1996", ("Thomas, P. C.", "et al."), 1996,
       "The shape of Ida", "Icarus 120 (title not confirmed; DOI not confirmed)"),
    _R("sierks2011", ("Sierks, H.", "Lamy, P.", "Barbieri, C.", "et al."), 2011,
       "Images of asteroid 21 Lutetia: A remnant planetesimal from the early solar system",
       "Science 334(6055), 487-490", "10.1126/science.1207325"),
    _R("willner2014", ("Willner, K.", "Shi, X.", "Oberst, J."), 2014,
       "Phobos' shape and topography models", "Planetary and Space Science",
       "10.1016/j.pss.2013.12.006"),
    # ---------------------------------------------------------------- presets: Eros
    _R("veverka2000", ("Veverka, J.", "et al."), 2000,
       "NEAR at Eros: Imaging and spectral results", "Science 289(5487), 2088-2097",
       "10.1126/science.289.5487.2088"),
    _R("chapman2002", ("Chapman, C. R.",), 2002,
       "Cratering on asteroids from Galileo and NEAR Shoemaker",
       "Asteroids III (Bottke, Cellino, Paolicchi & Binzel, eds.), University of Arizona "
       "Press, 315-330"),
    _R("berthoud2001", ("Berthoud, M.", "Thomas, P. C.", "Veverka, J."), 2001,
       "Eros: Crater densities in 3 major impact features",
       "Bulletin of the American Astronomical Society 33(3), DPS 2001 abstract 59.04"),
    _R("thomas2001", ("Thomas, P. C.", "et al."), 2001,
       "Shoemaker crater as the source of most ejecta blocks on the asteroid 433 Eros",
       "Nature 413(6854), 394-396 (PMID 11574880; DOI not confirmed)"),
    _R("michikami2021", ("Michikami, T.", "Hagermann, A."), 2021,
       "Boulder sizes and shapes on asteroids: A comparative study of Eros, Itokawa and "
       "Ryugu", "Icarus 357, 114282", "10.1016/j.icarus.2020.114282"),
    _R("yeomans2000", ("Yeomans, D. K.", "et al."),
       2000, "Radio science results during the NEAR-Shoemaker spacecraft rendezvous with "
       "Eros", "Science 289(5487), 2085-2088", "10.1126/science.289.5487.2085"),
    _R("zuber2000", ("Zuber, M. T.", "et al."), 2000,
       "The shape of 433 Eros from the NEAR-Shoemaker Laser Rangefinder",
       "Science 289(5487), 2097-2101", "10.1126/science.289.5487.2097"),
    # ---------------------------------------------------------------- presets: Itokawa
    _R("saito2006", ("Saito, J.", "et al."), 2006,
       "Detailed images of asteroid 25143 Itokawa from Hayabusa", "Science 312, 1341-1344",
       "10.1126/science.1125722"),
    _R("hirata2009", ("Hirata, N.", "et al."), 2009,
       "A survey of possible impact structures on 25143 Itokawa", "Icarus 200(2), 486-502",
       "10.1016/j.icarus.2008.10.027"),
    _R("michel2009", ("Michel, P.", "et al."), 2009,
       "Itokawa's cratering record as observed by Hayabusa: Implications for its age and "
       "collisional history", "Icarus 200(2), 503-513", "10.1016/j.icarus.2008.04.002"),
    _R("golombek1997", ("Golombek, M.", "Rapp, D."), 1997,
       "Size-frequency distributions of rocks on Mars and Earth analog sites: Implications "
       "for future landed missions", "Journal of Geophysical Research 102(E2), 4117-4129",
       "10.1029/96JE03319"),
    _R("golombek2003", ("Golombek, M. P.", "Matijevic, J. R.", "DiMaggio, E. N.",
                        "Schroeder, R. D."), 2003,
       "(title not confirmed; cited by venue)",
       "Lunar and Planetary Science XXXIV, abstract, NASA NTRS 20030111177"),
    _R("michikami2008", ("Michikami, T.", "et al."), 2008,
       "Size-frequency statistics of boulders on global surface of asteroid 25143 Itokawa",
       "Earth, Planets and Space 60, 13-20", "10.1186/BF03352757"),
    _R("fujiwara2006", ("Fujiwara, A.", "et al."), 2006,
       "The rubble-pile asteroid Itokawa as observed by Hayabusa", "Science 312, 1330-1334",
       "10.1126/science.1125841"),
    # ---------------------------------------------------------------- presets: Bennu
    _R("nolan2013", ("Nolan, M. C.", "et al."), 2013,
       "Shape model and surface properties of the OSIRIS-REx target asteroid (101955) Bennu "
       "from radar and lightcurve observations", "Icarus 226(1), 629-640 (DOI not confirmed)"),
    _R("bierhaus2022", ("Bierhaus, E. B.", "et al."), 2022,
       "Crater population on asteroid (101955) Bennu indicates impact armouring and a young "
       "surface", "Nature Geoscience 15 (title not confirmed; DOI not confirmed)"),
    _R("walsh2019", ("Walsh, K. J.", "Jawin, E. R.", "Ballouz, R.-L.", "et al."), 2019,
       "Craters, boulders and regolith of (101955) Bennu indicative of an old and dynamic "
       "surface", "Nature Geoscience 12, 242-246", "10.1038/s41561-019-0326-6"),
    _R("dellagiustina2019", ("DellaGiustina, D. N.", "et al."), 2019,
       "Properties of rubble-pile asteroid (101955) Bennu from OSIRIS-REx imaging and thermal "
       "analysis", "Nature Astronomy 3, 341-351", "10.1038/s41550-019-0731-1"),
    _R("scheeres2019", ("Scheeres, D. J.", "et al."), 2019,
       "The dynamic geophysical environment of (101955) Bennu based on OSIRIS-REx "
       "measurements", "Nature Astronomy 3(4), 352-361", "10.1038/s41550-019-0721-3"),
    # ---------------------------------------------------------------- gravity
    _R("werner1997", ("Werner, R. A.", "Scheeres, D. J."), 1997,
       "Exterior gravitation of a polyhedron derived and compared with harmonic and mascon "
       "gravitation representations of asteroid 4769 Castalia",
       "Celestial Mechanics and Dynamical Astronomy 65(3), 313-344 (issue dated 1996-97)",
       "10.1007/BF00053511"),
    _R("tsoulis2012", ("Tsoulis, D.",), 2012,
       "Analytical computation of the full gravity tensor of a homogeneous arbitrarily "
       "shaped polyhedral source using line integrals", "Geophysics 77(2), F1-F11",
       "10.1190/geo2010-0334.1"),
    _R("schuhmacher2024", ("Schuhmacher, J.", "et al."), 2024,
       "Efficient polyhedral gravity modeling in modern C++ and Python",
       "Journal of Open Source Software 9(98), 6384", "10.21105/joss.06384"),
    _R("tiesinga2021", ("Tiesinga, E.", "Mohr, P. J.", "Newell, D. B.", "Taylor, B. N."),
       2021, "CODATA recommended values of the fundamental physical constants: 2018",
       "Reviews of Modern Physics 93(2), 025010", "10.1103/RevModPhys.93.025010"),
    # ---------------------------------------------------------------- terrain
    _R("horn1981", ("Horn, B. K. P.",), 1981, "Hill shading and the reflectance map",
       "Proceedings of the IEEE 69(1), 14-47", "10.1109/PROC.1981.11918"),
    _R("zevenbergen1987", ("Zevenbergen, L. W.", "Thorne, C. R."), 1987,
       "Quantitative analysis of land surface topography",
       "Earth Surface Processes and Landforms 12(1), 47-56", "10.1002/esp.3290120107"),
    _R("peitgen1988", ("Peitgen, H.-O.", "Saupe, D."), 1988,
       "The Science of Fractal Images", "Springer, New York (editors)",
       "10.1007/978-1-4612-3784-6"),
    _R("rosenburg2011", ("Rosenburg, M. A.", "et al."), 2011,
       "Global surface slopes and roughness of the Moon from the Lunar Orbiter Laser "
       "Altimeter", "Journal of Geophysical Research 116, E02001", "10.1029/2010JE003716"),
    _R("perlin2002", ("Perlin, K.",), 2002, "Improving noise",
       "ACM Transactions on Graphics 21(3), 681-682", "10.1145/566654.566636"),
    _R("steele2014", ("Steele, G. L.", "Lea, D.", "Flood, C. H."), 2014,
       "Fast splittable pseudorandom number generators",
       "OOPSLA '14, ACM SIGPLAN Notices 49(10), 453-472", "10.1145/2660193.2660195"),
    # ---------------------------------------------------------------- implicit, meshes
    _R("wyvill1986", ("Wyvill, G.", "McPheeters, C.", "Wyvill, B."), 1986,
       "Data structure for soft objects", "The Visual Computer 2(4), 227-234",
       "10.1007/BF01900346"),
    _R("weller2010", ("Weller, R.", "Zachmann, G."), 2010,
       "ProtoSphere: A GPU-assisted prototype guided sphere packing algorithm for arbitrary "
       "objects", "SIGGRAPH Asia 2010 (DOI not confirmed)"),
    _R("zorin1996", ("Zorin, D.", "Schröder, P.", "Sweldens, W."), 1996,
       "Interpolating subdivision for meshes with arbitrary topology",
       "SIGGRAPH '96 Proceedings, 189-192", "10.1145/237170.237254"),
    _R("baerentzen2005", ("Bærentzen, J. A.", "Aanæs, H."), 2005,
       "Signed distance computation using the angle weighted pseudonormal",
       "IEEE Transactions on Visualization and Computer Graphics 11(3), 243-253",
       "10.1109/TVCG.2005.49"),
    _R("lagae2009", ("Lagae, A.", "Lefebvre, S.", "Drettakis, G.", "Dutré, P."), 2009,
       "Procedural noise using sparse Gabor convolution", "ACM Transactions on Graphics "
       "28(3), 54", "10.1145/1531326.1531360"),
    _R("galerne2012", ("Galerne, B.", "Lagae, A.", "Lefebvre, S.", "Drettakis, G."), 2012,
       "Gabor noise by example", "ACM Transactions on Graphics 31(4), 73",
       "10.1145/2185520.2185569"),
    _R("ericson2005", ("Ericson, C.",), 2005, "Real-Time Collision Detection",
       "Morgan Kaufmann, San Francisco"),
    _R("max1999", ("Max, N.",), 1999,
       "Weights for computing vertex normals from facet normals",
       "Journal of Graphics Tools 4(2), 1-6", "10.1080/10867651.1999.10487501"),
    # ---------------------------------------------------------------- numerics
    _R("moshier1989", ("Moshier, S. L.",), 1989,
       "Methods and Programs for Mathematical Functions",
       "Ellis Horwood, Chichester (book; its programs are the Cephes library)"),
    # ---------------------------------------------------------------- randomness
    _R("salmon2011", ("Salmon, J. K.", "Moraes, M. A.", "Dror, R. O.", "Shaw, D. E."), 2011,
       "Parallel random numbers: as easy as 1, 2, 3",
       "Proceedings of SC'11, the International Conference for High Performance Computing, "
       "Networking, Storage and Analysis (DOI not confirmed)"),
    # ---------------------------------------------------------------- sensors
    _R("moller1997", ("Möller, T.", "Trumbore, B."), 1997,
       "Fast, minimum storage ray-triangle intersection", "Journal of Graphics Tools 2(1), "
       "21-28", "10.1080/10867651.1997.10487468"),
    _R("wald2014", ("Wald, I.", "Woop, S.", "Benthin, C.", "Johnson, G. S.", "Ernst, M."),
       2014, "Embree: A kernel framework for efficient CPU ray tracing",
       "ACM Transactions on Graphics 33(4), 143", "10.1145/2601097.2601199"),
    _R("thurmer1998", ("Thürmer, G.", "Wüthrich, C. A."), 1998,
       "Computing vertex normals from polygonal facets",
       "Journal of Graphics Tools 3(1), 43-46"),
    _R("frisvad2012", ("Frisvad, J. R.",), 2012,
       "Building an orthonormal basis from a 3D unit vector without normalization",
       "Journal of Graphics Tools 16(3), 151-159 (DOI not confirmed)"),
    _R("dammertz2010", ("Dammertz, H.", "Sewtz, D.", "Hanika, J.", "Lensch, H. P. A."), 2010,
       "Edge-avoiding À-Trous wavelet transform for fast global illumination filtering",
       "Proceedings of High Performance Graphics 2010, 67-75 (DOI not confirmed)"),
    _R("knutsson1993", ("Knutsson, H.", "Westin, C.-F."), 1993,
       "Normalized and differential convolution: methods for interpolation and filtering "
       "of incomplete and uncertain data", "Proceedings of the IEEE Conference on Computer "
       "Vision and Pattern Recognition 1993, 515-523 (DOI not confirmed)"),
    _R("ingersoll1992", ("Ingersoll, A. P.", "Svitek, T.", "Murray, B. C."), 1992,
       "Stability of polar frosts in spherical bowl-shaped craters on the Moon, Mercury, "
       "and Mars", "Icarus 100(1), 40-47 (DOI not confirmed)"),
    _R("russell1916", ("Russell, H. N.",), 1916,
       "On the albedo of the planets and their satellites",
       "The Astrophysical Journal 43, 173-196"),
    _R("glenar2019", ("Glenar, D. A.", "Stubbs, T. J.", "Schwieterman, E. W.",
                      "Robinson, T. D.", "Livengood, T. A."), 2019,
       "Earthshine as an illumination source at the Moon",
       "Icarus 321, 841-856", "10.1016/j.icarus.2018.12.025"),
    _R("duff2017", ("Duff, T.", "Burgess, J.", "Christensen, P.", "et al."), 2017,
       "Building an orthonormal basis, revisited",
       "Journal of Computer Graphics Techniques 6(1), 1-8"),
    _R("hoffleit1991", ("Hoffleit, D.", "Warren, W. H., Jr."), 1991,
       "The Bright Star Catalogue, 5th Revised Ed. (Preliminary Version)",
       "NSSDC/ADC catalogue V/50; ADS 1991bsc..book.....H"),
    _R("willmer2018", ("Willmer, C. N. A.",), 2018,
       "The absolute magnitude of the Sun in several filters",
       "The Astrophysical Journal Supplement Series 236(2), 47", "10.3847/1538-4365/aabfdf"),
    _R("shepperd1978", ("Shepperd, S. W.",), 1978, "Quaternion from rotation matrix",
       "Journal of Guidance and Control 1(3), 223-224", "10.2514/3.55767b"),
    _R("brown1966", ("Brown, D. C.",), 1966, "Decentering distortion of lenses",
       "Photogrammetric Engineering 32(3), 444-462"),
    _R("conrady1919", ("Conrady, A. E.",), 1919, "Decentred lens-systems",
       "Monthly Notices of the Royal Astronomical Society 79(5), 384-390",
       "10.1093/mnras/79.5.384"),
    _R("hofle2007", ("Höfle, B.", "Pfeifer, N."), 2007,
       "Correction of laser scanning intensity data: Data and model-driven approaches",
       "ISPRS Journal of Photogrammetry and Remote Sensing 62(6), 415-433 (DOI not "
       "confirmed)"),
    _R("lommel1887", ("Lommel, E.",), 1887, "Die Photometrie der diffusen Zurückwerfung",
       "Sitzungsberichte der mathematisch-physikalischen Classe der k. bayerischen Akademie "
       "der Wissenschaften zu München 17"),
    _R("seeliger1888", ("Seeliger, H.",), 1888,
       "Zur Photometrie zerstreut reflectirender Substanzen",
       "Sitzungsberichte der mathematisch-physikalischen Classe der k. bayerischen Akademie "
       "der Wissenschaften zu München"),
    _R("mcewen1991", ("McEwen, A. S.",), 1991,
       "Photometric functions for photoclinometry and other applications",
       "Icarus 92(2), 298-311", "10.1016/0019-1035(91)90053-V"),
    _R("mcewen1996", ("McEwen, A. S.",), 1996, "A precise lunar photometric function",
       "27th Lunar and Planetary Science Conference, 841 (title not confirmed)"),
    _R("hapke1984", ("Hapke, B.",), 1984,
       "Bidirectional reflectance spectroscopy: 3. Correction for macroscopic roughness",
       "Icarus 59(1), 41-59", "10.1016/0019-1035(84)90054-X"),
    _R("hapke1986", ("Hapke, B.",), 1986,
       "Bidirectional reflectance spectroscopy: 4. The extinction coefficient and the "
       "opposition effect", "Icarus 67(2), 264-280 (DOI not confirmed)"),
    _R("hapke2002", ("Hapke, B.",), 2002,
       "Bidirectional reflectance spectroscopy: 5. The coherent backscatter opposition effect "
       "and anisotropic scattering", "Icarus 157(2), 523-534", "10.1006/icar.2002.6853"),
    _R("hapke2008", ("Hapke, B.",), 2008,
       "Bidirectional reflectance spectroscopy: 6. Effects of porosity",
       "Icarus 195, 918-926 (DOI not confirmed)"),
    _R("hapke2012", ("Hapke, B.",), 2012, "Theory of Reflectance and Emittance Spectroscopy",
       "Cambridge University Press, 2nd edition", "10.1017/CBO9781139025683"),
    _R("helfenstein1987", ("Helfenstein, P.", "Veverka, J."), 1987,
       "Photometric properties of lunar terrains derived from Hapke's equation",
       "Icarus 72, 342 (DOI not confirmed)"),
    _R("helfenstein1989", ("Helfenstein, P.", "Veverka, J."), 1989,
       "Physical characterization of asteroid surfaces from photometric analysis",
       "Asteroids II (Binzel, Gehrels & Matthews, eds.), University of Arizona Press, 557"),
    _R("ishiguro2014", ("Ishiguro, M.", "et al."), 2014,
       "Optical properties of (162173) 1999 JU3: In preparation for the JAXA Hayabusa 2 "
       "sample return mission", "The Astrophysical Journal 792(1), 74 (ADS 2014ApJ...792...74I)",
       "10.1088/0004-637X/792/1/74"),
    _R("li2004", ("Li, J.-Y.", "et al."), 2004,
       "Photometric analysis of Eros from NEAR data", "Icarus 172(2), 415-431 (title not "
       "confirmed; DOI not confirmed)"),
    _R("grier2001", ("Grier, J. A.", "McEwen, A. S.", "Lucey, P. G.", "Milazzo, M.",
                     "Strom, R. G."), 2001,
       "Optical maturity of ejecta from large rayed lunar craters",
       "Journal of Geophysical Research 106(E12), 32847-32862 (title not confirmed; DOI not "
       "confirmed)"),
)
del _R


def reference(key: str) -> Reference:
    """The :class:`Reference` of ``key`` (a key of :data:`REFERENCES`).

    Examples
    --------
    >>> reference("martin2014lunar").doi
    '10.1109/TAES.2014.120282'
    """
    try:
        return REFERENCES[key]
    except (KeyError, TypeError):
        near = difflib.get_close_matches(str(key), REFERENCES, n=3)
        hint = f" (did you mean {', '.join(near)}?)" if near else ""
        raise ValueError(f"`key` must be a key of craters.REFERENCES; got {key!r}{hint}") \
            from None
